"""The take file as the add-on reads it: numpy and the standard library only (Blender's
own Python runs it; it cannot import ecs_tentacles).

A take is a zip of `.npy` arrays (`ecs_tentacles.take.format`, versions 1 and 2). This
reads the header and the arrays an import needs, checked as untrusted input before
anything is allocated, and raises `TakeFileError` (one line naming the file and the
field) for a file that is not a sound take:

    with TakeFile(path) as take:
        take.header, take.frames, take.fps, take.creatures   # checked
        for first, arrays in take.blocks(("pos", "quat")):   # a block of frames at a time
            ...                                              # version 1: BLOCK_BYTES a read
        take.static("replay_clip.0")                          # arrays without a frames axis
        take.per_frame("replay_kind")                         # (frames, creatures) whole

Version 2 stores every array with a frames axis in chunks (`<name>.<k:05d>.npy`, frames
[k*C, (k+1)*C)); version 1 in one entry (`<name>.npy`), read here a block at a time. Each
entry's dtype and shape are read from its `.npy` header and compared with what the take's
header implies, and its stored size with the zip directory's, before its data is read.
"""

from __future__ import annotations

import json
import math
import re
import stat
import zipfile
import zlib
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Any, TypeGuard

import numpy as np

FORMAT = "ecs_tentacles.take"
VERSIONS = (1, 2)
MAX_HEADER_BYTES = 64 * 1024**2
MAX_FRAMES = 1_000_000
MAX_BODIES = 16384 * 1025
MAX_FPS = 1000
MAX_CHUNK_BYTES = 2 * 1024**3  # what one entry of a version 2 take may decode to
BLOCK_BYTES = 64 * 1024**2  # a version 1 array is read about this much at a time
MAX_COORDINATE = 1e6  # metres: farther out is a blow-up, not a creature
KINDS = 2  # replay kinds: 0 idle, 1 crawl
NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")  # a creature's name, as the take's header checks it
FLOATS = (np.dtype("<f4"), np.dtype("<f8"))
# arrays with a frames axis: name -> (dtypes accepted, the shape after the frames axis
# as a function of (bodies, creatures))
PER_FRAME: dict[str, tuple[tuple[np.dtype[Any], ...], Any]] = {
    "pos": (FLOATS, lambda b, c: (b, 3)),
    "quat": (FLOATS, lambda b, c: (b, 4)),
    "creature_visible": ((np.dtype("|b1"),), lambda b, c: (c,)),
    "replay_kind": ((np.dtype("|i1"),), lambda b, c: (c,)),
    "replay_phase": ((np.dtype("<f8"),), lambda b, c: (c,)),
    "replay_xy": ((np.dtype("<f8"),), lambda b, c: (c, 2)),
    "replay_heading": ((np.dtype("<f8"),), lambda b, c: (c,)),
}


class TakeFileError(ValueError):
    """A take cannot be imported; the message is one line naming the file and the field."""

    def __init__(self, message: str) -> None:
        super().__init__(" ".join(message.split()))


@dataclass(frozen=True)
class Creature:
    """One creature as the header lists it: `bodies` its take body indices, mantle first
    then the links tentacle by tentacle (the joints' order), `links` per tentacle."""

    name: str
    bodies: np.ndarray
    links: tuple[int, ...]


@dataclass(frozen=True)
class Clip:
    """A replay clip (`header.replay.clips[i]`): `bodies` per pose, seconds per clip frame,
    frames of each kind (idle, crawl)."""

    bodies: int
    dt: float
    frames: tuple[int, int]


def _number(value: object) -> TypeGuard[int | float]:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return False
    return math.isfinite(value) and abs(value) < 1e300


def _whole(value: object) -> TypeGuard[int]:
    return isinstance(value, int) and not isinstance(value, bool)


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
            self._check()
        except TakeFileError as error:
            self.archive.close()
            raise TakeFileError(f"{self.path}: {error}") from None
        except Exception as exc:
            self.archive.close()
            raise TakeFileError(
                f"{self.path}: not a take file ({type(exc).__name__}: {exc})"
            ) from None

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
        if not isinstance(header, dict) or header.get("format") != FORMAT:
            raise TakeFileError(f"header.format: expected {FORMAT!r}")
        return header

    def _check(self) -> None:
        """Check what the import reads of the header; sets frames, fps, creatures, clips."""
        header = self.header
        version = header.get("version")
        if version not in VERSIONS:
            raise TakeFileError(
                f"header.version: this add-on reads versions 1 and 2, got {version!r}"
            )
        self.version = int(version)
        fps = header.get("fps")
        if not _number(fps) or not 0 < fps <= MAX_FPS:
            raise TakeFileError(f"header.fps: must be a number in (0, {MAX_FPS}], got {fps!r}")
        self.fps = float(fps)
        frames = header.get("frames")
        if not _whole(frames) or not 1 <= frames <= MAX_FRAMES:
            raise TakeFileError(
                f"header.frames: must be a whole number in [1, {MAX_FRAMES}], got {frames!r}"
            )
        self.frames = int(frames)
        self.chunk_frames = self.frames
        if self.version == 2:
            chunk = header.get("chunk_frames")
            if not _whole(chunk) or chunk < 1:
                raise TakeFileError(
                    f"header.chunk_frames: must be a whole number >= 1, got {chunk!r}"
                )
            self.chunk_frames = int(chunk)
        bodies = header.get("bodies")
        if not isinstance(bodies, list) or len(bodies) > MAX_BODIES:
            raise TakeFileError(f"header.bodies: must be a list of at most {MAX_BODIES}")
        for b, body in enumerate(bodies):
            if not isinstance(body, dict) or not all(
                _number(body.get(k)) and 0 < body[k] <= 1e4 for k in ("radius", "length")
            ):
                raise TakeFileError(
                    f"header.bodies[{b}]: radius and length must be numbers in (0, 10000] m"
                )
        self.bodies = len(bodies)
        self.creatures = self._creatures(header.get("creatures"))
        self.clips, self.replayed = self._replay(
            header.get("replay") if self.version == 2 else None
        )
        self.roster = header.get("roster") is not None

    def _creatures(self, creatures: object) -> list[Creature]:
        if not isinstance(creatures, list) or not creatures:
            raise TakeFileError("header.creatures: must be a non-empty list")
        used: set[int] = set()
        names: set[str] = set()
        out = []
        for c, entry in enumerate(creatures):
            where = f"header.creatures[{c}]"
            if not isinstance(entry, dict):
                raise TakeFileError(f"{where}: not an object")
            name = entry.get("name")
            if not isinstance(name, str) or not NAME.fullmatch(name) or name in names:
                raise TakeFileError(f"{where}.name: must be a unique identifier, got {name!r}")
            names.add(name)
            chains = entry.get("tentacles")
            if (
                not isinstance(chains, list)
                or not chains
                or not all(isinstance(k, list) and k for k in chains)
            ):
                raise TakeFileError(
                    f"{where}.tentacles: must be a non-empty list of non-empty lists"
                )
            indices = [entry.get("mantle"), *(i for chain in chains for i in chain)]
            for index in indices:
                if not _whole(index) or not 0 <= index < self.bodies or index in used:
                    raise TakeFileError(
                        f"{where}: body index {index!r} is out of range or used twice"
                    )
                used.add(index)
            out.append(Creature(name, np.array(indices, np.int64), tuple(len(k) for k in chains)))
        return out

    def _replay(self, replay: object) -> tuple[list[Clip], np.ndarray]:
        """The clips and each creature's clip index (-1: never replayed)."""
        none = np.full(len(self.creatures), -1, np.int64)
        if replay is None:
            return [], none
        if not isinstance(replay, dict):
            raise TakeFileError("header.replay: must be null or an object")
        clips = replay.get("clips")
        if not isinstance(clips, list):
            raise TakeFileError("header.replay.clips: must be a list")
        out = []
        for i, clip in enumerate(clips):
            where = f"header.replay.clips[{i}]"
            if not isinstance(clip, dict):
                raise TakeFileError(f"{where}: not an object")
            bodies, dt, frames = clip.get("bodies"), clip.get("dt"), clip.get("frames")
            if not _whole(bodies) or not 1 <= bodies <= MAX_BODIES:
                raise TakeFileError(f"{where}.bodies: must be a whole number >= 1, got {bodies!r}")
            if not _number(dt) or not dt > 0:
                raise TakeFileError(f"{where}.dt: must be a number > 0, got {dt!r}")
            if (
                not isinstance(frames, list)
                or len(frames) != KINDS
                or not all(_whole(f) and 1 <= f <= MAX_FRAMES for f in frames)
            ):
                raise TakeFileError(f"{where}.frames: must be [idle, crawl] frame counts >= 1")
            out.append(Clip(int(bodies), float(dt), (int(frames[0]), int(frames[1]))))
        owners = replay.get("creatures")
        if not isinstance(owners, list) or len(owners) != len(self.creatures):
            raise TakeFileError("header.replay.creatures: must hold a clip index per creature")
        for c, clip in enumerate(owners):
            if not _whole(clip) or not -1 <= clip < len(out):
                raise TakeFileError(
                    f"header.replay.creatures[{c}]: must be a clip index or -1, got {clip!r}"
                )
            if clip >= 0 and out[clip].bodies != len(self.creatures[c].bodies):
                raise TakeFileError(
                    f"header.replay.creatures[{c}]: clip {clip} poses {out[clip].bodies} bodies,"
                    f" the creature has {len(self.creatures[c].bodies)}"
                )
        return out, np.array(owners, np.int64)

    # -- arrays --------------------------------------------------------------------------
    def has(self, name: str) -> bool:
        """Whether the take stores the per-frame array `name`."""
        return f"{name}.npy" in self.entries or f"{name}.00000.npy" in self.entries

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
        if self.version == 2:
            for k, first in enumerate(range(0, self.frames, self.chunk_frames)):
                count = min(self.chunk_frames, self.frames - first)
                yield first, {n: self._read(f"{n}.{k:05d}", n, count) for n in names}
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

    def _expected(self, name: str) -> tuple[tuple[np.dtype[Any], ...], tuple[int, ...]]:
        dtypes, rest = PER_FRAME[name]
        return dtypes, rest(self.bodies, len(self.creatures))

    def _read(self, filename: str, name: str, count: int) -> np.ndarray:
        """A version 2 chunk, checked (`count` frames) before its data is read."""
        entry = self._entry(f"{filename}.npy", filename)
        dtypes, rest = self._expected(name)
        with self.archive.open(entry) as handle:
            stored, dtype, fortran = _npy_header(handle, filename)
            if dtype not in dtypes or stored != (count, *rest):
                raise TakeFileError(
                    f"{filename}: dtype {dtype} shape {stored}, expected"
                    f" {' or '.join(map(str, dtypes))} {(count, *rest)}"
                )
            size = math.prod(stored) * dtype.itemsize
            if size > MAX_CHUNK_BYTES:
                raise TakeFileError(
                    f"{filename}: {size} bytes, over the {MAX_CHUNK_BYTES} a chunk holds"
                )
            self._sized(entry, handle, filename, size)
            return _data(handle, filename, stored, dtype, fortran)

    def _stream(self, name: str) -> tuple[IO[bytes], tuple[int, ...], np.dtype[Any]]:
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


def _npy_header(handle: IO[bytes], name: str) -> tuple[tuple[int, ...], np.dtype[Any], bool]:
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
    handle: IO[bytes], name: str, shape: tuple[int, ...], dtype: np.dtype[Any], fortran: bool
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
    name: str, handle: IO[bytes], rest: tuple[int, ...], dtype: np.dtype[Any], count: int
) -> np.ndarray:
    """The next `count` frames of a version 1 array being streamed."""
    return _data(handle, name, (count, *rest), dtype, False)
