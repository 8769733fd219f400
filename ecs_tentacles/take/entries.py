"""Reading a take archive's entries as untrusted input: nothing allocated before it is checked.

`checked_header` reads and checks an archive's header (`ecs_tentacles.take.header`);
`read_npy` reads one `.npy` entry after checking its dtype, that its data is there and
its shape; `data_problem` finds the first number no take may hold. Used by both
layouts' readers (`take.read`: whole arrays; `take.chunked_read`: chunks).
"""

from __future__ import annotations

import json
import math
import zipfile
from collections.abc import Callable, Iterator
from typing import IO, Any, cast

import numpy as np

from ecs_tentacles.take import compact
from ecs_tentacles.take.header import (
    CORE_DTYPES,
    MAX_COORDINATE,
    MAX_HEADER_BYTES,
    TakeError,
    header_problem,
)
from ecs_tentacles.take.tracks import TakeTrack
from ecs_tentacles.untrusted import bounded_json
from ecs_tentacles.untrusted.bounded_json import JsonLimit


def _npy_header(handle: IO[bytes], name: str) -> tuple[tuple[int, ...], bool, np.dtype]:
    try:
        version = np.lib.format.read_magic(handle)
        if version == (1, 0):
            return np.lib.format.read_array_header_1_0(handle)
        return np.lib.format.read_array_header_2_0(handle)
    except (ValueError, SyntaxError, TypeError, EOFError) as exc:
        raise TakeError(f"{name}: not a .npy array ({exc})") from None


def _read_entry(
    archive: zipfile.ZipFile, name: str, shape: tuple[int, ...] | None, wanted: np.dtype[np.generic]
) -> np.ndarray:
    """Read `name`.npy, checking dtype and `shape` (None: any 4-d) before allocating."""

    def check(stored: tuple[int, ...]) -> str | None:
        if shape is None and (len(stored) != 4 or stored[2] < 2 or stored[3] != 3):
            return f"shape {stored}, expected (frames, curves, points >= 2, 3)"
        if shape is not None and stored != shape:
            return f"shape {stored}, expected {shape} from the header"
        return None

    return read_npy(archive, f"{name}.npy", name, wanted, check)


def read_npy(
    archive: zipfile.ZipFile,
    entry_name: str,
    label: str,
    wanted: np.dtype[np.generic],
    check: Callable[[tuple[int, ...]], str | None],
) -> np.ndarray:
    """Read entry `entry_name` (an .npy), checking its dtype, that its data is there and
    `check(shape)` (a problem or None) before allocating; errors name `label`."""
    entry = archive.getinfo(entry_name)
    with archive.open(entry) as handle:
        stored, fortran, dtype = _npy_header(handle, label)
        if dtype != wanted:
            raise TakeError(f"{label}: dtype {dtype}, expected {wanted}")
        if math.prod(stored) * dtype.itemsize > entry.file_size:
            raise TakeError(f"{label}: shape {tuple(stored)} holds more than the stored data")
        if entry.file_size > math.prod(stored) * dtype.itemsize + NPY_HEADER_ROOM:
            raise TakeError(  # a zip directory that lies: refused before inflating
                f"{label}: the archive claims {entry.file_size} bytes for shape {tuple(stored)}"
            )
        problem = check(tuple(stored))
        if problem:
            raise TakeError(f"{label}: {problem}")
        array = np.empty(stored[::-1], dtype).T if fortran else np.empty(stored, dtype)
        empty = memoryview(b"")  # an empty array (a track with no items): nothing to read
        view = (array.T if fortran else array).data.cast("B") if array.size else empty
        filled = 0
        while filled < len(view):  # in pieces: zip's readinto reads all it is asked into a copy
            piece = view[filled : filled + READ_PIECE]
            count = handle.readinto(piece)  # type: ignore[attr-defined]
            if not count:
                raise TakeError(f"{label}: data is cut short ({filled} of {len(view)} bytes)")
            filled += count
        if handle.read(1):
            raise TakeError(f"{label}: more data than its shape {tuple(stored)} holds")
    return array


NPY_HEADER_ROOM = 64 * 1024  # an .npy entry's bytes beyond its data: its header, at most
READ_PIECE = 4 * 1024**2  # bytes an entry is read in at a time
CHECK_BYTES = 16 * 1024**2  # the checks below look at this much of an array at a time


def _blocks(array: np.ndarray) -> Iterator[tuple[int, np.ndarray]]:
    """(first frame, view) blocks of `array` along its first axis, about CHECK_BYTES each,
    so checking a take costs a few blocks of memory on top of the take, not copies of it."""
    rows = max(1, CHECK_BYTES // max(1, array[:1].nbytes))
    for first in range(0, len(array), rows):
        yield first, array[first : first + rows]


def data_problem(
    arrays: dict[str, np.ndarray], tracks: list[TakeTrack] | None = None, frame: int = 0
) -> str | None:
    """The first non-finite number, number beyond `MAX_COORDINATE`, negative width (of
    `tracks`' curves) or zero quaternion in `arrays`, or None. Checked block by block
    (`CHECK_BYTES`); frame indices counted from `frame` (the first of `arrays`)."""
    for name, array in arrays.items():
        if array.dtype.kind != "f":
            continue
        for first, block in _blocks(array):
            bad = ~np.isfinite(block)
            if bad.any():
                where = np.argwhere(bad)[0]
                where[0] += first + frame
                return f"{name}: non-finite value {array[tuple(where)]} at {tuple(where.tolist())}"
            far = np.abs(block) > MAX_COORDINATE
            if far.any():
                where = np.argwhere(far)[0]
                where[0] += first + frame
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
            at, body = np.argwhere(short)[0].tolist()
            return f"quat: zero-length quaternion at frame {frame + first + at}, body {body}"
    return None


def checked_header(archive: zipfile.ZipFile) -> dict[str, Any]:
    """The archive's header, read within `MAX_HEADER_BYTES` and checked (`header_problem`);
    raises `TakeError` (one line) when it is missing or unsound, or an entry is repeated."""
    names = [entry.filename for entry in archive.infolist()]
    if len(set(names)) != len(names):
        raise TakeError("an array is stored twice")
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
    try:
        header = compact.unpacked(header)
    except compact.PlanError as exc:
        raise TakeError(str(exc)) from None
    problem = header_problem(header)
    if problem:
        raise TakeError(problem)
    return cast(dict[str, Any], header)


def _header_shape(archive: zipfile.ZipFile) -> tuple[int, ...]:
    """The header is 1-d uint8: its length is whatever the stored array says (checked)."""
    with archive.open("header.npy") as handle:
        stored, _, _ = _npy_header(handle, "header")
    if len(stored) != 1:
        raise TakeError(f"header: shape {tuple(stored)}, expected 1-d bytes")
    return tuple(stored)
