"""Reading a take file as untrusted input: nothing is allocated before it is checked.

A take may be hand-edited, truncated or hostile. `read_take` returns the header and
the arrays only when all of this holds, else raises `TakeError` with one line:

- the file is a regular file and a zip archive whose entries are exactly the arrays
  the format defines (`take.ARRAYS`, no unknown or repeated entries);
- the uncompressed size the zip directory claims is at most `max_bytes` (a zip bomb
  is refused before anything is inflated), and so is the size the header implies;
- the header is UTF-8 JSON describing creatures, bodies, suckers, goals and guides
  with the names, indices and numbers the exporters need (`header_problem`);
- every array's stored dtype and shape (read from its `.npy` header before its data)
  are the ones the header implies, its data is complete and its CRC right;
- every float is finite and every quaternion has a length.
"""

from __future__ import annotations

import json
import math
import re
import stat
import zipfile
import zlib
from pathlib import Path
from typing import IO, Any, cast

import numpy as np

MAX_TAKE_BYTES = 2 * 1024**3  # uncompressed; a 10 s bake of 4 creatures is ~30 MB
MAX_HEADER_BYTES = 64 * 1024**2
FORMAT = "ecs_tentacles.take"
VERSION = 1
DTYPES: dict[str, np.dtype[Any]] = {
    "header": np.dtype(np.uint8),
    "pos": np.dtype("<f4"),
    "quat": np.dtype("<f4"),
    "sucker_attached": np.dtype(np.bool_),
    "sucker_anchor": np.dtype("<f4"),
    "goal_pos": np.dtype("<f4"),
    "goal_active": np.dtype(np.bool_),
    "guide_points": np.dtype("<f4"),
    "guide_widths": np.dtype("<f4"),
}
OPTIONAL = ("guide_points", "guide_widths")
AXES = ("X", "Y", "Z")
_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")


class TakeError(ValueError):
    """A take file cannot be read; the message is one line naming the file and the problem."""

    def __init__(self, message: str) -> None:
        super().__init__(" ".join(message.split()))  # one line, whatever a library said


def _is_int(value: object) -> bool:
    return isinstance(value, int) and not isinstance(value, bool)


def _is_number(value: object) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)


def _index(value: object, size: int) -> bool:
    return isinstance(value, int) and not isinstance(value, bool) and 0 <= value < size


def _list_of_dicts(header: dict[str, Any], key: str) -> str | None:
    value = header.get(key)
    if not isinstance(value, list):
        return f"header.{key}: missing or not a list"
    for i, item in enumerate(value):
        if not isinstance(item, dict):
            return f"header.{key}[{i}]: not an object"
    return None


def _creature_problem(creatures: list[dict[str, Any]], bodies: int) -> str | None:
    used: set[int] = set()
    names: set[str] = set()
    for c, creature in enumerate(creatures):
        where = f"header.creatures[{c}]"
        name = creature.get("name")
        if not isinstance(name, str) or not _NAME.match(name) or name in names:
            return f"{where}.name: must be a unique identifier (letters, digits, _), got {name!r}"
        names.add(name)
        chains = creature.get("tentacles")
        if not isinstance(chains, list) or not all(isinstance(k, list) for k in chains):
            return f"{where}.tentacles: must be a list of lists of body indices"
        for index in [creature.get("mantle"), *(i for chain in chains for i in chain)]:
            if not _index(index, bodies) or index in used:
                return f"{where}: body index {index!r} is out of range or used twice"
            used.add(index)
    return None


def _body_problem(header: dict[str, Any]) -> str | None:
    creatures = header["creatures"]
    for b, body in enumerate(header["bodies"]):
        where = f"header.bodies[{b}]"
        owner = body.get("creature")
        if not _index(owner, len(creatures)):
            return f"{where}.creature: must be a creature index, got {owner!r}"
        pattern = rf"^{creatures[owner]['name']}/(mantle|tentacles/t\d+/link\d+)$"
        if not isinstance(body.get("name"), str) or not re.match(pattern, body["name"]):
            return f"{where}.name: must be <creature>/mantle or .../tentacles/t<k>/link<i>"
        if body.get("shape") not in ("cylinder", "capsule") or body.get("axis") not in AXES:
            return f"{where}: shape must be cylinder or capsule, axis X, Y or Z"
        if not all(_is_number(body.get(k)) and 0 < body[k] <= 1e4 for k in ("radius", "length")):
            return f"{where}: radius and length must be numbers in (0, 10000] m"
    names = [body["name"] for body in header["bodies"]]
    if len(set(names)) != len(names):
        return "header.bodies: two bodies have the same name"
    return None


def _parts_problem(header: dict[str, Any]) -> str | None:
    bodies, creatures = header["bodies"], header["creatures"]
    for s, sucker in enumerate(header["suckers"]):
        where = f"header.suckers[{s}]"
        if not _index(sucker.get("body"), len(bodies)):
            return f"{where}.body: must be a body index, got {sucker.get('body')!r}"
        pattern = rf"^{re.escape(bodies[sucker['body']]['name'])}/sucker\d+$"
        if not isinstance(sucker.get("name"), str) or not re.match(pattern, sucker["name"]):
            return f"{where}.name: must be <body>/sucker<n>"
        offset = sucker.get("offset")
        if not isinstance(offset, list) or len(offset) != 3 or not all(map(_is_number, offset)):
            return f"{where}.offset: must be 3 finite numbers"
    for g, goal in enumerate(header["goals"]):
        where = f"header.goals[{g}]"
        if not _index(goal.get("creature"), len(creatures)):
            return f"{where}.creature: must be a creature index, got {goal.get('creature')!r}"
        pattern = rf"^{creatures[goal['creature']]['name']}/goals/goal\d+$"
        if not isinstance(goal.get("name"), str) or not re.match(pattern, goal["name"]):
            return f"{where}.name: must be <creature>/goals/goal<n>"
        if not _is_number(goal.get("radius")) or goal["radius"] < 0:
            return f"{where}.radius: must be a finite number >= 0"
    for key in ("suckers", "goals"):
        names = [item["name"] for item in header[key]]
        if len(set(names)) != len(names):
            return f"header.{key}: two have the same name"
    guides = header.get("guides")
    if guides is not None:
        owners = guides.get("creatures") if isinstance(guides, dict) else None
        if not isinstance(owners, list) or not all(
            _is_int(o) and -1 <= o < len(creatures) for o in owners
        ):
            return "header.guides.creatures: must be a list of creature indices (or -1)"
    return None


def header_problem(header: object) -> str | None:
    """The first problem of a take header as a one-line `header.<path>: <what>`, or None."""
    if not isinstance(header, dict) or header.get("format") != FORMAT:
        return f"header.format: expected {FORMAT!r}"
    if header.get("version") != VERSION:
        return f"header.version: this reader knows version {VERSION}, got {header.get('version')!r}"
    fps: Any = header.get("fps")
    if not _is_number(fps) or fps <= 0:
        return f"header.fps: must be a finite number > 0, got {fps!r}"
    if not _is_int(header.get("frames")) or header["frames"] < 1:
        return f"header.frames: must be a whole number >= 1, got {header.get('frames')!r}"
    for key, check in (("scene", str), ("scene_sha256", str)):
        if not isinstance(header.get(key), check):
            return f"header.{key}: missing or not a string"
    if not _is_int(header.get("seed")):
        return "header.seed: missing or not a whole number"
    for key in ("creatures", "bodies", "suckers", "goals"):
        problem = _list_of_dicts(header, key)
        if problem:
            return problem
    return (
        _creature_problem(header["creatures"], len(header["bodies"]))
        or _body_problem(header)
        or _parts_problem(header)
    )


def expected_shapes(header: dict[str, Any], points: int | None) -> dict[str, tuple[int, ...]]:
    """Array name -> shape implied by a sound header (guides' points: from the file)."""
    frames, bodies = header["frames"], len(header["bodies"])
    suckers, goals = len(header["suckers"]), len(header["goals"])
    shapes: dict[str, tuple[int, ...]] = {
        "pos": (frames, bodies, 3),
        "quat": (frames, bodies, 4),
        "sucker_attached": (frames, suckers),
        "sucker_anchor": (frames, suckers, 3),
        "goal_pos": (goals, 3),
        "goal_active": (frames, goals),
    }
    if header.get("guides") is not None and points is not None:
        guides = len(header["guides"]["creatures"])
        shapes["guide_points"] = (frames, guides, points, 3)
        shapes["guide_widths"] = (frames, guides, points)
    return shapes


def _npy_header(handle: IO[bytes], name: str) -> tuple[tuple[int, ...], bool, np.dtype]:
    try:
        version = np.lib.format.read_magic(handle)
        if version == (1, 0):
            return np.lib.format.read_array_header_1_0(handle)
        return np.lib.format.read_array_header_2_0(handle)
    except (ValueError, SyntaxError, TypeError, EOFError) as exc:
        raise TakeError(f"{name}: not a .npy array ({exc})") from None


def _read_entry(archive: zipfile.ZipFile, name: str, shape: tuple[int, ...] | None) -> np.ndarray:
    """Read `name`.npy, checking dtype and `shape` (None: any 4-d) before allocating."""
    entry = archive.getinfo(f"{name}.npy")
    with archive.open(entry) as handle:
        stored, fortran, dtype = _npy_header(handle, name)
        if dtype != DTYPES[name]:
            raise TakeError(f"{name}: dtype {dtype}, expected {DTYPES[name]}")
        if math.prod(stored) * dtype.itemsize > entry.file_size:
            raise TakeError(f"{name}: shape {tuple(stored)} holds more than the stored data")
        if shape is None and (len(stored) != 4 or stored[2] < 2 or stored[3] != 3):
            raise TakeError(
                f"{name}: shape {tuple(stored)}, expected (frames, guides, points >= 2, 3)"
            )
        if shape is not None and tuple(stored) != shape:
            raise TakeError(f"{name}: shape {tuple(stored)}, expected {shape} from the header")
        array = np.empty(stored[::-1], dtype).T if fortran else np.empty(stored, dtype)
        empty = memoryview(b"")  # an empty array (a take without goals): nothing to read
        view = (
            memoryview(cast(Any, array.T if fortran else array)).cast("B") if array.size else empty
        )
        filled = 0
        while filled < len(view):
            count = handle.readinto(view[filled:])  # type: ignore[attr-defined]
            if not count:
                raise TakeError(f"{name}: data is cut short ({filled} of {len(view)} bytes)")
            filled += count
        if handle.read(1):
            raise TakeError(f"{name}: more data than its shape {tuple(stored)} holds")
    return array


def data_problem(arrays: dict[str, np.ndarray]) -> str | None:
    """The first non-finite number, negative width or zero quaternion in `arrays`, or None."""
    for name, array in arrays.items():
        if array.dtype.kind == "f" and not np.isfinite(array).all():
            where = np.argwhere(~np.isfinite(array))[0]
            return f"{name}: non-finite value {array[tuple(where)]} at {tuple(where.tolist())}"
    if (arrays["guide_widths"] < 0).any() if "guide_widths" in arrays else False:
        return "guide_widths: negative width"
    lengths = np.linalg.norm(arrays["quat"].astype(np.float64), axis=-1)
    if (lengths < 1e-6).any():
        frame, body = np.argwhere(lengths < 1e-6)[0].tolist()
        return f"quat: zero-length quaternion at frame {frame}, body {body}"
    return None


def read_take(
    path: str | Path, max_bytes: int = MAX_TAKE_BYTES
) -> tuple[dict[str, Any], dict[str, np.ndarray]]:
    """Header and arrays of a take file, checked as described in the module docstring."""
    where = Path(path)
    try:
        info = where.stat()
    except FileNotFoundError:
        raise TakeError(f"{where}: no such file") from None
    except OSError as exc:
        raise TakeError(f"{where}: cannot read: {exc.strerror}") from None
    if not stat.S_ISREG(info.st_mode):
        raise TakeError(f"{where}: not a regular file")
    if not zipfile.is_zipfile(where):
        raise TakeError(f"{where}: not a take file (not an npz archive)")
    try:
        with zipfile.ZipFile(where) as archive:
            return _read_archive(archive, max_bytes)
    except TakeError as error:
        raise TakeError(f"{where}: {error}") from None
    except (
        zipfile.BadZipFile,
        zipfile.LargeZipFile,
        zlib.error,
        EOFError,
        OSError,
        ValueError,
    ) as exc:
        raise TakeError(f"{where}: not a take file ({type(exc).__name__}: {exc})") from None
    except NotImplementedError as exc:  # e.g. an unsupported compression method
        raise TakeError(f"{where}: not a take file ({exc})") from None


def _read_archive(
    archive: zipfile.ZipFile, max_bytes: int
) -> tuple[dict[str, Any], dict[str, np.ndarray]]:
    entries = archive.infolist()
    names = [entry.filename for entry in entries]
    known = {f"{name}.npy" for name in DTYPES}
    for name in names:
        if name not in known:
            raise TakeError(f"unknown entry {name!r} (a take holds {', '.join(sorted(known))})")
    if len(set(names)) != len(names):
        raise TakeError("an array is stored twice")
    claimed = sum(entry.file_size for entry in entries)
    if claimed > max_bytes:
        raise TakeError(f"arrays would expand to {claimed} bytes, over the {max_bytes} limit")
    if "header.npy" not in names:
        raise TakeError("not a take file (no header)")
    if archive.getinfo("header.npy").file_size > MAX_HEADER_BYTES:
        raise TakeError(f"header: larger than {MAX_HEADER_BYTES} bytes")
    raw = _read_entry(archive, "header", _header_shape(archive))
    try:
        header = json.loads(raw.tobytes().decode())
    except (UnicodeDecodeError, json.JSONDecodeError, RecursionError) as exc:
        raise TakeError(f"header: not JSON ({str(exc).splitlines()[0]})") from None
    problem = header_problem(header)
    if problem:
        raise TakeError(problem)
    guided = header.get("guides") is not None
    for name in OPTIONAL:
        if (f"{name}.npy" in names) != guided:
            raise TakeError(f"{name}: present only when header.guides is")
    arrays: dict[str, np.ndarray] = {}
    shapes = expected_shapes(header, points=0)
    implied = sum(math.prod(s) * DTYPES[n].itemsize for n, s in shapes.items())
    if implied > max_bytes:
        raise TakeError(f"header implies {implied} bytes of arrays, over the {max_bytes} limit")
    for name in DTYPES:
        if name == "header" or name in OPTIONAL:
            continue
        if f"{name}.npy" not in names:
            raise TakeError(f"{name}: missing")
        arrays[name] = _read_entry(archive, name, shapes[name])
    if guided:
        arrays["guide_points"] = _read_entry(archive, "guide_points", None)
        shapes = expected_shapes(header, points=arrays["guide_points"].shape[2])
        for name in OPTIONAL:
            if name in arrays and arrays[name].shape != shapes[name]:
                raise TakeError(f"{name}: shape {arrays[name].shape}, expected {shapes[name]}")
        arrays["guide_widths"] = _read_entry(archive, "guide_widths", shapes["guide_widths"])
    problem = data_problem(arrays)
    if problem:
        raise TakeError(problem)
    return header, arrays


def _header_shape(archive: zipfile.ZipFile) -> tuple[int, ...]:
    """The header is 1-d uint8: its length is whatever the stored array says (checked)."""
    with archive.open("header.npy") as handle:
        stored, _, _ = _npy_header(handle, "header")
    if len(stored) != 1:
        raise TakeError(f"header: shape {tuple(stored)}, expected 1-d bytes")
    return tuple(stored)
