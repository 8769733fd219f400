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
import stat
import zipfile
import zlib
from collections.abc import Iterator
from pathlib import Path
from typing import IO, Any, cast

import numpy as np

from ecs_tentacles.take import ground as take_ground
from ecs_tentacles.take.header import (
    CORE_DTYPES,
    FORMAT,
    MAX_COORDINATE,
    MAX_FRAMES,
    MAX_HEADER_BYTES,
    MAX_TAKE_BYTES,
    VERSION,
    TakeError,
    array_dtypes,
    expected_shapes,
    header_problem,
)
from ecs_tentacles.take.tracks import TakeTrack, tracks_of
from ecs_tentacles.untrusted import bounded_json
from ecs_tentacles.untrusted.bounded_json import JsonLimit

__all__ = [
    "FORMAT",
    "MAX_FRAMES",
    "MAX_HEADER_BYTES",
    "MAX_TAKE_BYTES",
    "VERSION",
    "TakeError",
    "array_dtypes",
    "data_problem",
    "expected_shapes",
    "header_problem",
    "read_take",
]


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
