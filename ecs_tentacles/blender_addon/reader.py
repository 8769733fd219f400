"""The take file as the add-on reads it: numpy and the standard library only (Blender's
own Python runs it; it cannot import ecs_tentacles).

A take is a zip of `.npy` arrays (`ecs_tentacles.take.format`, versions 1 to 3). This
reads the header and the arrays an import needs, checked as untrusted input before
anything is allocated, and raises `TakeFileError` (one line naming the file and the
field) for a file that is not a sound take:

    with TakeFile(path) as take:
        take.header, take.frames, take.fps, take.creatures   # checked (`header.check`)
        for first, arrays in take.blocks(("pos", "quat")):   # a block of frames at a time
            ...                                              # version 1: BLOCK_BYTES a read
        take.static("replay_clip_0")                          # arrays without a frames axis
        take.per_frame("replay_kind")                         # (frames, creatures) whole

Version 2 stores its big per-frame arrays (`header.chunked`: poses, suckers, replay
records) in chunks (`<name>.<k:06d>.npy`, frames [k*C, (k+1)*C), C = `chunk_frames`; a
creature spawned while the bake wrote is missing from the chunks before it came: it gets
its values at the first frame of the first chunk holding everyone, as the project's
reader gives it), the others in one entry (`<name>.npy`), as version 1 does every array
(read here a block of frames at a time). Each entry's dtype and shape are read from its
`.npy` header and compared with what the take's header implies, and its stored size with
the zip directory's, before its data is read.
"""

from __future__ import annotations

import json
import math
import stat
import zipfile
import zlib
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import IO, Any, cast

import numpy as np

from .header import Clip, Creature, TakeFileError, check
from .shared import module

__all__ = ["Clip", "Creature", "TakeFile", "TakeFileError", "value_problem"]
MAX_HEADER_BYTES = 64 * 1024**2
MAX_CHUNK_BYTES = 2 * 1024**3  # what one entry of a version 2 take may decode to
BLOCK_BYTES = 16 * 1024**2  # a version 1 take is read about this much at a time
MAX_COORDINATE = 1e6  # metres: farther out is a blow-up, not a creature
FLOATS = (np.dtype("<f4"),)
# arrays with a frames axis: name -> (dtypes accepted, the shape after the frames axis
# as a function of (bodies, creatures))
PER_FRAME: dict[
    str, tuple[tuple[np.dtype[np.generic], ...], Callable[[int, int], tuple[int, ...]]]
] = {
    "pos": (FLOATS, lambda b, c: (b, 3)),
    "quat": (FLOATS, lambda b, c: (b, 4)),
    "creature_visible": ((np.dtype("|b1"),), lambda b, c: (c,)),
    "replay_kind": ((np.dtype("|i1"),), lambda b, c: (c,)),
    "replay_phase": ((np.dtype("<f8"),), lambda b, c: (c,)),
    "replay_xy": ((np.dtype("<f8"),), lambda b, c: (c, 2)),
    "replay_heading": ((np.dtype("<f8"),), lambda b, c: (c,)),
}


class TakeFile:
    """An open take: its checked header and its arrays on demand (see the module)."""

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
        try:
            info = self.path.stat()
        except FileNotFoundError:
            raise TakeFileError(f"{self.path}: no such file") from None
        except OSError as exc:
            raise TakeFileError(f"{self.path}: cannot read: {exc.strerror}") from None
        if not stat.S_ISREG(info.st_mode):
            raise TakeFileError(f"{self.path}: not a regular file")
        try:
            self.archive = zipfile.ZipFile(self.path)
        except (zipfile.BadZipFile, OSError, ValueError) as exc:
            raise TakeFileError(
                f"{self.path}: not a take file (not an npz archive: {exc})"
            ) from None
        try:
            self.entries = {entry.filename: entry for entry in self.archive.infolist()}
            self.header = self._header()
            checked = check(self.header)
        except TakeFileError as error:
            self.archive.close()
            raise TakeFileError(f"{self.path}: {error}") from None
        except Exception as exc:
            self.archive.close()
            raise TakeFileError(
                f"{self.path}: not a take file ({type(exc).__name__}: {exc})"
            ) from None
        self.version, self.fps, self.frames = checked.version, checked.fps, checked.frames
        self.chunk_frames, self.bodies = checked.chunk_frames, checked.bodies
        self.creatures, self.clips = checked.creatures, checked.clips
        self.replayed, self.roster = checked.replayed, checked.roster
        self.chunked = checked.chunked
        self._later: dict[tuple[str, int], np.ndarray] = {}

    def __enter__(self) -> TakeFile:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        """Close the archive."""
        self.archive.close()

    # -- the header ----------------------------------------------------------------------
    def _header(self) -> dict[str, Any]:
        entry = self.entries.get("header.npy")
        if entry is None:
            raise TakeFileError("not a take file (no header)")
        if entry.file_size > MAX_HEADER_BYTES:
            raise TakeFileError(f"header: larger than {MAX_HEADER_BYTES} bytes")
        with self.archive.open(entry) as handle:
            shape, dtype, _ = _npy_header(handle, "header")
            if dtype != np.dtype("|u1") or len(shape) != 1:
                raise TakeFileError(f"header: dtype {dtype} shape {shape}, expected 1-d uint8")
            text = handle.read(shape[0] + 1)
        if len(text) != shape[0]:
            raise TakeFileError(f"header: {len(text)} bytes stored, its shape says {shape[0]}")
        try:
            header = json.loads(text.decode("utf-8"))
        except (UnicodeDecodeError, ValueError, RecursionError) as exc:
            raise TakeFileError(f"header: not JSON ({str(exc).splitlines()[0]})") from None
        if not isinstance(header, dict):
            raise TakeFileError("header: not a JSON object")
        compact = module("take_compact")
        try:
            return cast(dict[str, Any], compact.unpacked(header))
        except compact.PlanError as exc:
            raise TakeFileError(str(exc)) from None

    # -- arrays --------------------------------------------------------------------------
    def blocks(self, names: tuple[str, ...]) -> Iterator[tuple[int, dict[str, np.ndarray]]]:
        """(first frame, {name: block}) over the take: blocks of the per-frame arrays
        `names`, each (n, ...) for frames [first, first + n), their floats checked finite
        and within `MAX_COORDINATE`."""
        try:
            for first, block in self._blocks(names):
                for name, array in block.items():
                    problem = value_problem(name, array, first)
                    if problem:
                        raise TakeFileError(problem)
                yield first, block
        except TakeFileError as error:
            raise self._located(error) from None

    def _blocks(self, names: tuple[str, ...]) -> Iterator[tuple[int, dict[str, np.ndarray]]]:
        if self.version >= 2:
            whole = {n: self._whole(n) for n in names if n not in self.chunked}
            for k, first in enumerate(range(0, self.frames, self.chunk_frames)):
                count = min(self.chunk_frames, self.frames - first)
                yield (
                    first,
                    {
                        n: self._chunk(n, k)
                        if n in self.chunked
                        else whole[n][first : first + count]
                        for n in names
                    },
                )
            return
        handles = {n: self._stream(n) for n in names}
        try:
            width = sum(math.prod(shape) * dtype.itemsize for _, shape, dtype in handles.values())
            rows = max(1, BLOCK_BYTES // max(1, width))
            for first in range(0, self.frames, rows):
                count = min(rows, self.frames - first)
                yield first, {n: _rows(n, *handles[n], count) for n in names}
        finally:
            for handle, _, _ in handles.values():
                handle.close()

    def _whole(self, name: str) -> np.ndarray:
        """A per-frame array stored in one entry (a version 2 take's unchunked ones)."""
        handle, rest, dtype = self._stream(name)
        with handle:
            return _rows(name, handle, rest, dtype, self.frames)

    def per_frame(self, name: str) -> np.ndarray:
        """The whole per-frame array `name` (for the small ones: a value per creature)."""
        parts = [block[name] for _, block in self.blocks((name,))]
        return np.concatenate(parts)

    def static(self, name: str, shape: tuple[int, ...], dtype: str) -> np.ndarray:
        """The array `name` without a frames axis, checked to be `shape` of `dtype`."""
        try:
            entry = self._entry(f"{name}.npy", name)
            with self.archive.open(entry) as handle:
                stored, got, fortran = _npy_header(handle, name)
                if got != np.dtype(dtype) or stored != shape:
                    raise TakeFileError(
                        f"{name}: dtype {got} shape {stored}, expected {np.dtype(dtype)} {shape}"
                    )
                self._sized(entry, handle, name, math.prod(shape) * got.itemsize)
                array = _data(handle, name, stored, got, fortran)
            problem = value_problem(name, array)
            if problem:
                raise TakeFileError(problem)
            return array
        except TakeFileError as error:
            raise self._located(error) from None

    def _entry(self, filename: str, name: str) -> zipfile.ZipInfo:
        entry = self.entries.get(filename)
        if entry is None:
            raise TakeFileError(f"{name}: missing ({filename})")
        return entry

    def _expected(self, name: str) -> tuple[tuple[np.dtype[np.generic], ...], tuple[int, ...]]:
        dtypes, rest = PER_FRAME[name]
        return dtypes, rest(self.bodies, len(self.creatures))

    def _chunk(self, name: str, k: int) -> np.ndarray:
        """Chunk `k` of `name`; items (bodies, creatures) that came later than the chunk
        hold their values at the first frame of the first chunk holding every item."""
        value = self._read(name, k, 0)
        items = self._expected(name)[1][0]
        have = value.shape[1]
        if have == items:
            return value
        key = (name, have)
        if key not in self._later:
            for j in range(k + 1, math.ceil(self.frames / self.chunk_frames)):
                later = self._read(name, j, have)
                if later.shape[1] == items:
                    self._later[key] = np.array(later[0, have:])
                    break
            else:
                raise TakeFileError(f"{name}: no chunk holds all its {items} items")
        out = np.empty((value.shape[0], items, *value.shape[2:]), value.dtype)
        out[:, :have] = value
        out[:, have:] = self._later[key]
        return out

    def _read(self, name: str, k: int, at_least: int) -> np.ndarray:
        """Chunk `k` of `name` as stored, checked before its data is read: its frames,
        between `at_least` items and the header's (creatures spawned while a bake wrote
        the take are missing from its earlier chunks), the rest of its shape, its size."""
        label = f"{name} chunk {k}"
        entry = self._entry(f"{name}.{k:06d}.npy", label)
        count = min(self.chunk_frames, self.frames - k * self.chunk_frames)
        dtypes, rest = self._expected(name)
        with self.archive.open(entry) as handle:
            stored, dtype, fortran = _npy_header(handle, label)
            if (
                dtype not in dtypes
                or len(stored) != 1 + len(rest)
                or stored[0] != count
                or stored[2:] != rest[1:]
                or not at_least <= stored[1] <= rest[0]
            ):
                expected = (count, f"{at_least}..{rest[0]}", *rest[1:])
                raise TakeFileError(
                    f"{label}: dtype {dtype} shape {stored}, expected"
                    f" {' or '.join(map(str, dtypes))} {expected}".replace("'", "")
                )
            size = math.prod(stored) * dtype.itemsize
            if size > MAX_CHUNK_BYTES:
                raise TakeFileError(
                    f"{label}: {size} bytes, over the {MAX_CHUNK_BYTES} a chunk holds"
                )
            self._sized(entry, handle, label, size)
            return _data(handle, label, stored, dtype, fortran)

    def _stream(self, name: str) -> tuple[IO[bytes], tuple[int, ...], np.dtype[np.generic]]:
        """A version 1 array's entry, checked and opened at its data; (handle, the shape of
        a frame, dtype). A Fortran-ordered array is refused (numpy writes C order)."""
        entry = self._entry(f"{name}.npy", name)
        dtypes, rest = self._expected(name)
        handle = self.archive.open(entry)
        try:
            stored, dtype, fortran = _npy_header(handle, name)
            if dtype not in dtypes or stored != (self.frames, *rest):
                raise TakeFileError(
                    f"{name}: dtype {dtype} shape {stored}, expected"
                    f" {' or '.join(map(str, dtypes))} {(self.frames, *rest)}"
                )
            if fortran and len(stored) > 1:
                raise TakeFileError(f"{name}: stored in Fortran order; this reader reads C order")
            self._sized(entry, handle, name, math.prod(stored) * dtype.itemsize)
        except BaseException:
            handle.close()
            raise
        return handle, tuple(rest), dtype

    def _sized(self, entry: zipfile.ZipInfo, handle: IO[bytes], name: str, size: int) -> None:
        if entry.file_size - handle.tell() != size:
            raise TakeFileError(
                f"{name}: {entry.file_size - handle.tell()} bytes stored, its shape holds {size}"
            )

    def _located(self, error: TakeFileError) -> TakeFileError:
        """`error` with this file's name in front (once)."""
        text = str(error)
        return error if text.startswith(f"{self.path}: ") else TakeFileError(f"{self.path}: {text}")


def value_problem(name: str, array: np.ndarray, first: int = 0) -> str | None:
    """The first non-finite float of `array`, or one beyond `MAX_COORDINATE` (its index:
    the first axis counted from `first`), or None."""
    if array.dtype.kind != "f":
        return None
    bad = ~np.isfinite(array) | (np.abs(array) > MAX_COORDINATE)
    if not bad.any():
        return None
    where = np.argwhere(bad)[0]
    value = float(array[tuple(where)])
    where[0] += first
    at = tuple(where.tolist())
    return f"{name}: {value!r} at {at} is not a finite number within {MAX_COORDINATE:g} m"


def _npy_header(handle: IO[bytes], name: str) -> tuple[tuple[int, ...], np.dtype[np.generic], bool]:
    try:
        version = np.lib.format.read_magic(handle)
        if version == (1, 0):
            shape, fortran, dtype = np.lib.format.read_array_header_1_0(handle)
        else:
            shape, fortran, dtype = np.lib.format.read_array_header_2_0(handle)
    except (ValueError, SyntaxError, TypeError, EOFError, zlib.error, zipfile.BadZipFile) as exc:
        raise TakeFileError(f"{name}: not a .npy array ({exc})") from None
    if dtype.hasobject:
        raise TakeFileError(f"{name}: holds Python objects, not numbers")
    return tuple(int(n) for n in shape), dtype, bool(fortran)


def _data(
    handle: IO[bytes], name: str, shape: tuple[int, ...], dtype: np.dtype[np.generic], fortran: bool
) -> np.ndarray:
    """The rest of `handle`: the data of a checked `.npy` entry."""
    size = math.prod(shape) * dtype.itemsize
    try:
        data = handle.read(size)
    except (zlib.error, zipfile.BadZipFile, EOFError, OSError) as exc:
        raise TakeFileError(f"{name}: cannot be read ({exc})") from None
    if len(data) != size:
        raise TakeFileError(f"{name}: data is cut short ({len(data)} of {size} bytes)")
    array = np.frombuffer(data, dtype)
    if fortran:
        return array.reshape(shape[::-1]).T
    return array.reshape(shape)


def _rows(
    name: str, handle: IO[bytes], rest: tuple[int, ...], dtype: np.dtype[np.generic], count: int
) -> np.ndarray:
    """The next `count` frames of a version 1 array being streamed."""
    return _data(handle, name, (count, *rest), dtype, False)
