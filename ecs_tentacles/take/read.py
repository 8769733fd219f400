"""Reading a take file as untrusted input: nothing is allocated before it is checked.

A take may be hand-edited, truncated or hostile. `read_take` returns the header and
the arrays only when all of this holds, else raises `TakeError` with one line:

- the file is a regular file and a zip archive whose entries are exactly the arrays
  the format defines: bodies, suckers and the tracks (`ecs_tentacles.take.tracks`:
  the standard ones and those the header declares), no unknown or repeated entries;
- the uncompressed size the zip directory claims is at most `max_bytes` (a zip bomb
  is refused before anything is inflated), and so is the size the header implies;
- the header is UTF-8 JSON describing creatures, bodies, suckers and every track
  (points: name, creature, radius each; curves: an owner per curve) with the names,
  indices and numbers the exporters need (`header_problem`), and the ground's meshes
  when there are any (`ecs_tentacles.take.ground`; their triangle indices in range);
- every array's stored dtype and shape (read from its `.npy` header before its data)
  are the ones the header implies, its data is complete and its CRC right;
- every float is finite and every quaternion has a length.
"""

from __future__ import annotations

import json
import math
import re
import stat
import sys
import zipfile
import zlib
from collections.abc import Iterator
from pathlib import Path
from typing import IO, Any, cast

import numpy as np

from ecs_tentacles.take import ground as take_ground
from ecs_tentacles.take import roster as take_roster
from ecs_tentacles.take.tracks import TakeTrack, declared_problem, dtypes, tracks_of
from ecs_tentacles.untrusted import bounded_json
from ecs_tentacles.untrusted.bounded_json import JsonLimit

MAX_TAKE_BYTES = 2 * 1024**3  # uncompressed; a 10 s bake of 4 creatures is ~30 MB
MAX_HEADER_BYTES = 64 * 1024**2
MAX_FPS = 1000  # the scene schema's and `bake --fps`'s highest rate
MAX_COORDINATE = 1e6  # metres: a position farther out is a blow-up, not a creature
MAX_FRAMES = 1_000_000  # 4.6 hours at 60 fps: frames are bounded even with no bodies
MAX_BODIES = 16384 * 1025  # the schema's most creatures x the bodies of its largest one
FORMAT = "ecs_tentacles.take"
VERSION = 1
CORE_DTYPES: dict[str, np.dtype[Any]] = {
    "header": np.dtype(np.uint8),
    "pos": np.dtype("<f4"),
    "quat": np.dtype("<f4"),
    "sucker_attached": np.dtype(np.bool_),
    "sucker_anchor": np.dtype("<f4"),
}
AXES = ("X", "Y", "Z")
_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")


class TakeError(ValueError):
    """A take file cannot be read; the message is one line naming the file and the problem."""

    def __init__(self, message: str) -> None:
        super().__init__(" ".join(message.split()))  # one line, whatever a library said


def _is_int(value: object) -> bool:
    return isinstance(value, int) and not isinstance(value, bool)


def _is_number(value: object) -> bool:
    """A finite number a float can hold (an int too large for one is not)."""
    if isinstance(value, float):
        return math.isfinite(value)
    return _is_int(value) and abs(cast(int, value)) <= sys.float_info.max


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
        if not isinstance(name, str) or not _NAME.fullmatch(name) or name in names:
            return f"{where}.name: must be a unique identifier (letters, digits, _), got {name!r}"
        names.add(name)
        chains = creature.get("tentacles")
        if not isinstance(chains, list) or not all(isinstance(k, list) for k in chains):
            return f"{where}.tentacles: must be a list of lists of body indices"
        if not chains:  # the exporters' skeletons need a tentacle of a link at least
            return f"{where}.tentacles: a creature needs at least one tentacle, got 0"
        empty = next((k for k, chain in enumerate(chains) if not chain), None)
        if empty is not None:
            return f"{where}.tentacles[{empty}]: a tentacle needs at least one link, got 0"
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
        if not isinstance(body.get("name"), str) or not re.fullmatch(pattern, body["name"]):
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
    bodies = header["bodies"]
    for s, sucker in enumerate(header["suckers"]):
        where = f"header.suckers[{s}]"
        if not _index(sucker.get("body"), len(bodies)):
            return f"{where}.body: must be a body index, got {sucker.get('body')!r}"
        pattern = rf"^{re.escape(bodies[sucker['body']]['name'])}/sucker\d+$"
        if not isinstance(sucker.get("name"), str) or not re.fullmatch(pattern, sucker["name"]):
            return f"{where}.name: must be <body>/sucker<n>"
        offset = sucker.get("offset")
        if not isinstance(offset, list) or len(offset) != 3 or not all(map(_is_number, offset)):
            return f"{where}.offset: must be 3 finite numbers"
    names = [item["name"] for item in header["suckers"]]
    if len(set(names)) != len(names):
        return "header.suckers: two have the same name"
    for track in tracks_of(header):
        problem = _track_problem(header, track)
        if problem:
            return problem
    return None


def _track_problem(header: dict[str, Any], track: TakeTrack) -> str | None:
    """The first problem of a track's header entry (`take_tracks` describes both kinds)."""
    creatures, key = header["creatures"], track.key
    if track.kind == "curves":
        curves = header.get(key)
        if curves is None:
            return None
        owners = curves.get("creatures") if isinstance(curves, dict) else None
        if not isinstance(owners, list) or not all(
            _is_int(o) and -1 <= o < len(creatures) for o in owners
        ):
            return f"header.{key}.creatures: must be a list of creature indices (or -1)"
        return None
    problem = _list_of_dicts(header, key)
    if problem:
        return problem
    for i, item in enumerate(header[key]):
        where = f"header.{key}[{i}]"
        if not _index(item.get("creature"), len(creatures)):
            return f"{where}.creature: must be a creature index, got {item.get('creature')!r}"
        stem = f"{track.folder}/{track.item}"
        pattern = rf"^{creatures[item['creature']]['name']}/{stem}\d+$"
        if not isinstance(item.get("name"), str) or not re.fullmatch(pattern, item["name"]):
            return f"{where}.name: must be <creature>/{stem}<n>"
        if not _is_number(item.get("radius")) or not 0 <= item["radius"] <= MAX_COORDINATE:
            return f"{where}.radius: must be a number in [0, {MAX_COORDINATE:g}] m"
    names = [item["name"] for item in header[key]]
    if len(set(names)) != len(names):
        return f"header.{key}: two have the same name"
    return None


def header_problem(header: object) -> str | None:
    """The first problem of a take header as a one-line `header.<path>: <what>`, or None."""
    if not isinstance(header, dict) or header.get("format") != FORMAT:
        return f"header.format: expected {FORMAT!r}"
    if header.get("version") != VERSION:
        return f"header.version: this reader knows version {VERSION}, got {header.get('version')!r}"
    fps: Any = header.get("fps")
    if not _is_number(fps) or not 0 < fps <= MAX_FPS:
        return f"header.fps: must be a number in (0, {MAX_FPS}], got {fps!r}"
    if not _is_int(header.get("frames")) or header["frames"] < 1:
        return f"header.frames: must be a whole number >= 1, got {header.get('frames')!r}"
    if header["frames"] > MAX_FRAMES:
        return f"header.frames: at most {MAX_FRAMES} in a take, got {header['frames']}"
    for key, check in (("scene", str), ("scene_sha256", str)):
        if not isinstance(header.get(key), check):
            return f"header.{key}: missing or not a string"
    if not _is_int(header.get("seed")):
        return "header.seed: missing or not a whole number"
    for key in ("creatures", "bodies", "suckers"):
        problem = _list_of_dicts(header, key)
        if problem:
            return problem
        if len(header[key]) > MAX_BODIES:
            return f"header.{key}: at most {MAX_BODIES} in a take, got {len(header[key])}"
    return (
        declared_problem(header)
        or _creature_problem(header["creatures"], len(header["bodies"]))
        or _body_problem(header)
        or _parts_problem(header)
        or take_ground.problem(header)
        or take_roster.problem(header)
    )


def expected_shapes(
    header: dict[str, Any], points: dict[str, int] | None = None
) -> dict[str, tuple[int, ...]]:
    """Array name -> shape implied by a sound header (curves' points per curve: from
    `points`, by the curves' first array name; curves not in it are left out)."""
    frames, bodies, suckers = header["frames"], len(header["bodies"]), len(header["suckers"])
    shapes: dict[str, tuple[int, ...]] = {
        "pos": (frames, bodies, 3),
        "quat": (frames, bodies, 4),
        "sucker_attached": (frames, suckers),
        "sucker_anchor": (frames, suckers, 3),
    }
    points = points or {}
    for track in tracks_of(header):
        first, second = track.arrays
        if track.kind == "points":
            items = len(header[track.key])
            shapes[first], shapes[second] = (items, 3), (frames, items)
        elif header.get(track.key) is not None and first in points:
            curves = len(header[track.key]["creatures"])
            shapes[first] = (frames, curves, points[first], 3)
            shapes[second] = (frames, curves, points[first])
    shapes.update(take_ground.shapes(header))
    shapes.update(take_roster.shapes(header))
    return shapes


def array_dtypes(header: dict[str, Any]) -> dict[str, np.dtype[Any]]:
    """Every array a take with this (sound) header may hold -> its dtype, in file order."""
    out = dict(CORE_DTYPES)
    for track in tracks_of(header):
        for name, dtype in zip(track.arrays, dtypes(track), strict=True):
            out[name] = np.dtype(dtype)
    out.update(take_ground.dtypes(header))
    out.update(take_roster.dtypes(header))
    return out


def _npy_header(handle: IO[bytes], name: str) -> tuple[tuple[int, ...], bool, np.dtype]:
    try:
        version = np.lib.format.read_magic(handle)
        if version == (1, 0):
            return np.lib.format.read_array_header_1_0(handle)
        return np.lib.format.read_array_header_2_0(handle)
    except (ValueError, SyntaxError, TypeError, EOFError) as exc:
        raise TakeError(f"{name}: not a .npy array ({exc})") from None


def _read_entry(
    archive: zipfile.ZipFile, name: str, shape: tuple[int, ...] | None, wanted: np.dtype[Any]
) -> np.ndarray:
    """Read `name`.npy, checking dtype and `shape` (None: any 4-d) before allocating."""
    entry = archive.getinfo(f"{name}.npy")
    with archive.open(entry) as handle:
        stored, fortran, dtype = _npy_header(handle, name)
        if dtype != wanted:
            raise TakeError(f"{name}: dtype {dtype}, expected {wanted}")
        if math.prod(stored) * dtype.itemsize > entry.file_size:
            raise TakeError(f"{name}: shape {tuple(stored)} holds more than the stored data")
        if shape is None and (len(stored) != 4 or stored[2] < 2 or stored[3] != 3):
            raise TakeError(
                f"{name}: shape {tuple(stored)}, expected (frames, curves, points >= 2, 3)"
            )
        if shape is not None and tuple(stored) != shape:
            raise TakeError(f"{name}: shape {tuple(stored)}, expected {shape} from the header")
        array = np.empty(stored[::-1], dtype).T if fortran else np.empty(stored, dtype)
        empty = memoryview(b"")  # an empty array (a track with no items): nothing to read
        view = (
            memoryview(cast(Any, array.T if fortran else array)).cast("B") if array.size else empty
        )
        filled = 0
        while filled < len(view):  # in pieces: zip's readinto reads all it is asked into a copy
            piece = view[filled : filled + READ_PIECE]
            count = handle.readinto(piece)  # type: ignore[attr-defined]
            if not count:
                raise TakeError(f"{name}: data is cut short ({filled} of {len(view)} bytes)")
            filled += count
        if handle.read(1):
            raise TakeError(f"{name}: more data than its shape {tuple(stored)} holds")
    return array


READ_PIECE = 4 * 1024**2  # bytes an entry is read in at a time
CHECK_BYTES = 16 * 1024**2  # the checks below look at this much of an array at a time


def _blocks(array: np.ndarray) -> Iterator[tuple[int, np.ndarray]]:
    """(first frame, view) blocks of `array` along its first axis, about CHECK_BYTES each,
    so checking a take costs a few blocks of memory on top of the take, not copies of it."""
    rows = max(1, CHECK_BYTES // max(1, array[:1].nbytes))
    for first in range(0, len(array), rows):
        yield first, array[first : first + rows]


def data_problem(
    arrays: dict[str, np.ndarray], tracks: list[TakeTrack] | None = None
) -> str | None:
    """The first non-finite number, number beyond `MAX_COORDINATE`, negative width (of
    `tracks`' curves) or zero quaternion in `arrays`, or None. Checked block by block
    (`CHECK_BYTES`)."""
    for name, array in arrays.items():
        if array.dtype.kind != "f":
            continue
        for first, block in _blocks(array):
            bad = ~np.isfinite(block)
            if bad.any():
                where = np.argwhere(bad)[0]
                where[0] += first
                return f"{name}: non-finite value {array[tuple(where)]} at {tuple(where.tolist())}"
            far = np.abs(block) > MAX_COORDINATE
            if far.any():
                where = np.argwhere(far)[0]
                where[0] += first
                value = array[tuple(where)]
                return (
                    f"{name}: {value:g} at {tuple(where.tolist())} is beyond {MAX_COORDINATE:g} m"
                )
    for track in tracks or []:
        widths = arrays.get(track.arrays[1]) if track.kind == "curves" else None
        if widths is not None and any((block < 0).any() for _, block in _blocks(widths)):
            return f"{track.arrays[1]}: negative width"
    for first, block in _blocks(arrays["quat"]):
        short = np.einsum("...i,...i->...", block, block) < 1e-12  # length under 1e-6
        if short.any():
            frame, body = np.argwhere(short)[0].tolist()
            return f"quat: zero-length quaternion at frame {first + frame}, body {body}"
    return None


def read_take(
    path: str | Path, max_bytes: int = MAX_TAKE_BYTES, header_only: bool = False
) -> tuple[dict[str, Any], dict[str, np.ndarray]]:
    """Header and arrays of a take file, checked as described in the module docstring;
    `header_only`: the checked header and no arrays (nothing past the header is read)."""
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
            return _read_archive(archive, max_bytes, header_only)
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
    archive: zipfile.ZipFile, max_bytes: int, header_only: bool = False
) -> tuple[dict[str, Any], dict[str, np.ndarray]]:
    entries = archive.infolist()
    names = [entry.filename for entry in entries]
    if len(set(names)) != len(names):
        raise TakeError("an array is stored twice")
    claimed = sum(entry.file_size for entry in entries)
    if claimed > max_bytes:
        raise TakeError(f"arrays would expand to {claimed} bytes, over the {max_bytes} limit")
    if "header.npy" not in names:
        raise TakeError("not a take file (no header)")
    if archive.getinfo("header.npy").file_size > MAX_HEADER_BYTES:
        raise TakeError(f"header: larger than {MAX_HEADER_BYTES} bytes")
    raw = _read_entry(archive, "header", _header_shape(archive), CORE_DTYPES["header"])
    try:
        header = bounded_json.loads(raw.tobytes().decode(), "header", max_bytes=MAX_HEADER_BYTES)
    except JsonLimit as exc:
        raise TakeError(str(exc)) from None
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise TakeError(f"header: not JSON ({str(exc).splitlines()[0]})") from None
    problem = header_problem(header)
    if problem:
        raise TakeError(problem)
    if header_only:
        return header, {}
    wanted = array_dtypes(header)
    known = {f"{name}.npy" for name in wanted}
    for name in names:
        if name not in known:
            raise TakeError(f"unknown entry {name!r} (a take holds {', '.join(sorted(known))})")
    tracks = tracks_of(header)
    optional = {a for t in tracks if t.kind == "curves" and header[t.key] is None for a in t.arrays}
    for track in tracks:
        if track.kind != "curves":
            continue
        for name in track.arrays:
            if (f"{name}.npy" in names) != (header[track.key] is not None):
                raise TakeError(f"{name}: present only when header.{track.key} is")
    shapes = expected_shapes(header)
    implied = sum(math.prod(s) * wanted[n].itemsize for n, s in shapes.items())
    if implied > max_bytes:
        raise TakeError(f"header implies {implied} bytes of arrays, over the {max_bytes} limit")
    arrays: dict[str, np.ndarray] = {}
    for name in wanted:
        if name == "header" or name in optional:
            continue
        if f"{name}.npy" not in names:
            raise TakeError(f"{name}: missing")
        if name not in shapes:  # the first array of curves: its points come from the file
            arrays[name] = _read_entry(archive, name, None, wanted[name])
            shapes = expected_shapes(header, {name: arrays[name].shape[2]})
            if arrays[name].shape != shapes[name]:
                raise TakeError(f"{name}: shape {arrays[name].shape}, expected {shapes[name]}")
            continue
        arrays[name] = _read_entry(archive, name, shapes[name], wanted[name])
    problem = data_problem(arrays, tracks) or take_ground.index_problem(header, arrays)
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
