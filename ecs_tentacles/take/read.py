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

import math
import stat
import zipfile
import zlib
from pathlib import Path
from typing import Any

import numpy as np

from ecs_tentacles.take import ground as take_ground
from ecs_tentacles.take.chunked_read import read_whole
from ecs_tentacles.take.entries import (
    CHECK_BYTES,
    READ_PIECE,
    _read_entry,
    checked_header,
    data_problem,
    read_npy,
)
from ecs_tentacles.take.header import (
    FORMAT,
    MAX_FRAMES,
    MAX_HEADER_BYTES,
    MAX_TAKE_BYTES,
    VERSION,
    TakeError,
    array_dtypes,
    expected_shapes,
    header_problem,
)
from ecs_tentacles.take.tracks import tracks_of

__all__ = [
    "CHECK_BYTES",
    "FORMAT",
    "MAX_FRAMES",
    "MAX_HEADER_BYTES",
    "MAX_TAKE_BYTES",
    "READ_PIECE",
    "VERSION",
    "TakeError",
    "array_dtypes",
    "checked_header",
    "data_problem",
    "expected_shapes",
    "header_problem",
    "read_npy",
    "read_take",
]


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
    names = [entry.filename for entry in archive.infolist()]
    claimed = sum(entry.file_size for entry in archive.infolist())
    if claimed > max_bytes and not header_only:  # read whole: a zip bomb is refused here
        raise TakeError(f"arrays would expand to {claimed} bytes, over the {max_bytes} limit")
    header = checked_header(archive)
    if header_only:
        return header, {}
    if header["version"] >= 2:
        return header, read_whole(archive, header, max_bytes)
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
