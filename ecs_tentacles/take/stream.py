"""Reading a take a chunk of frames at a time: `open_take` (versions 1 to 3).

    with open_take("shot.npz") as source:
        source.header, source.frames, source.fps
        for first, chunk in source.chunks():        # a `Take` of frames [first, first + n)
            ...                                     # every pose there (replayed filled in)
        source.segments(creature)                   # its replayed stretches
        source.clip_pose(clip)                      # a clip's frames, ground frame

Each chunk is checked as `read_take` checks a whole take (dtypes, shapes against the
header, finite values, rotations with a length, replay records that make poses) before
it is handed out; the arrays without a frames axis are read and checked once. What is
decoded at once is capped (`max_bytes`: a chunk of every per-frame array with the arrays
without frames), not the shot. A version 1 file is read whole and handed out in slices.
"""

from __future__ import annotations

import functools
import stat
import zipfile
import zlib
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ecs_tentacles.take import chunks
from ecs_tentacles.take import ground as take_ground
from ecs_tentacles.take import replay as take_replay
from ecs_tentacles.take.chunked_read import Layout, frame_arrays
from ecs_tentacles.take.entries import checked_header, data_problem
from ecs_tentacles.take.format import Take
from ecs_tentacles.take.header import (
    MAX_TAKE_BYTES,
    TakeError,
)
from ecs_tentacles.take.tracks import tracks_of
from ecs_tentacles.untrusted.files import ClosedOnExit

__all__ = ["ReplaySegment", "TakeSource", "open_take"]


@dataclass(frozen=True)
class ReplaySegment:
    """Take frames [first, end) show clip `clip`'s `kind` loop at clip frame
    `phase + (f - first) * rate`, placed at the creature's root motion of frame f."""

    first: int
    end: int
    clip: int
    kind: int
    phase: float
    rate: float


class TakeSource(ClosedOnExit):
    """An open take: its checked header, arrays without frames, and chunks of frames."""

    def __init__(self, path: str | Path, max_bytes: int = MAX_TAKE_BYTES) -> None:
        self.path = where = Path(path)
        self._take: Take | None = None
        self._archive: Layout | None = None
        self._zip: zipfile.ZipFile | None = None
        self._replay: dict[str, np.ndarray] | None = None
        try:
            info = where.stat()
            if not stat.S_ISREG(info.st_mode):
                raise TakeError(f"{where}: not a regular file")
            if not zipfile.is_zipfile(where):
                raise TakeError(f"{where}: not a take file (not an npz archive)")
            self._zip = zipfile.ZipFile(where)
            self.header = checked_header(self._zip)
            if self.header["version"] == 1:
                self._zip.close()
                self._zip = None
                self._take = Take.load(where, max_bytes)
                self.header, self.static = self._take.header, self._v1_static(self._take)
                return
            self._archive = Layout(self._zip, self.header, max_bytes)
            self.static = {n: self._archive.single(n) for n in self._archive.singles}
            self._clips = {
                i: self.static[take_replay.clip_array(i)]
                for i in range(len((self.header.get(take_replay.KEY) or {}).get("clips", [])))
            }
            problem = take_replay.clips_problem(self.header, self._clips)
            problem = problem or take_ground.index_problem(self.header, self.static)
            if problem:
                raise TakeError(problem)
        except FileNotFoundError:
            self.close()
            raise TakeError(f"{where}: no such file") from None
        except (TakeError, *_UNSOUND) as error:
            self.close()
            raise _named(where, error) from None

    @staticmethod
    def _v1_static(take: Take) -> dict[str, np.ndarray]:
        per_frame = frame_arrays(take.header)
        return {name: value for name, value in take.tracks.items() if name not in per_frame}

    # -- closing --------------------------------------------------------------------------
    def close(self) -> None:
        if self._zip is not None:
            self._zip.close()
            self._zip = None

    # -- what it holds --------------------------------------------------------------------
    @property
    def frames(self) -> int:
        return int(self.header["frames"])

    @property
    def fps(self) -> float:
        return float(self.header["fps"])

    @property
    def chunk_frames(self) -> int:
        """Frames a chunk holds (the last may hold fewer)."""
        return int(self.header.get("chunk_frames", self.frames))

    def clip_pose(self, clip: int) -> np.ndarray:
        """Clip `clip`'s frames (F_idle + F_crawl, B, 7) in the ground frame, take order."""
        return self._clips[clip]

    def chunks(
        self,
        frames: int | None = None,
        bodies: np.ndarray | None = None,
        whole: np.ndarray | None = None,
    ) -> Iterator[tuple[int, Take]]:
        """(first frame, a `Take` of the next frames) for the whole take, in order; each
        chunk holds `frames` frames (default: the file's chunk), the last fewer.

        `bodies`: a replayed creature's bodies posed, but where `whole` (frames,
        creatures) says (`replay.fill`): the rest at the origin, unrotated. Default: all.
        """
        step = frames or self.chunk_frames
        read = functools.partial(self._chunk, bodies=bodies, whole=whole)
        if self._take is not None:  # version 1: read whole
            for first in range(0, self.frames, step):
                yield first, _slice(self._take, first, min(first + step, self.frames))
            return
        archive = self._archive
        assert archive is not None, "the take is closed"
        buffered: Take | None = None
        for k in range(archive.count):
            piece = self._named(read, k)
            buffered = piece if buffered is None else _join(buffered, piece)
            while buffered is not None and buffered.frames >= step:
                first = k * archive.per_chunk + piece.frames - buffered.frames
                yield first, _slice(buffered, 0, step)
                buffered = (
                    _slice(buffered, step, buffered.frames) if buffered.frames > step else None
                )
        if buffered is not None:
            yield self.frames - buffered.frames, buffered

    def _named(self, read: Callable[[int], Take], k: int) -> Take:
        """`read(k)`, its failures as one line naming the file (`TakeError`)."""
        try:
            return read(k)
        except (TakeError, *_UNSOUND) as error:
            raise _named(self.path, error) from None

    def _padded(self, name: str, k: int) -> np.ndarray:
        """Chunk `k` of `name`, items it lacks (spawned later) at their first values."""
        archive = self._archive
        assert archive is not None
        value = archive.chunk(name, k, 0)
        if value.shape[1] < archive.items[name]:
            value = chunks.pad_items(value, archive.items[name], self._later(name, k, value))
        return value

    def _chunk(
        self, k: int, bodies: np.ndarray | None = None, whole: np.ndarray | None = None
    ) -> Take:
        archive = self._archive
        assert archive is not None
        header = self.header
        first = k * archive.per_chunk
        end = min(first + archive.per_chunk, self.frames)
        arrays = {name: self._padded(name, k) for name in archive.chunked}
        for name in archive.singles:
            if name in archive.frame_singles:
                arrays[name] = self.static[name][first:end]
        problem = take_replay.values_problem(header, arrays) if self._clips else None
        if problem:
            raise TakeError(f"{self.path}: {problem}")
        part = None if whole is None else whole[first:end]
        owners = None if bodies is None else self._body_owners
        take_replay.fill(
            header, self._clips, arrays, arrays["pos"], arrays["quat"], bodies, part, owners
        )
        checked = {n: a for n, a in arrays.items() if n not in take_replay.PER_FRAME}
        problem = data_problem(checked, tracks_of(header))
        if problem:
            raise TakeError(f"{self.path}: frames {first}-{end - 1}: {problem}")
        piece_header = {**header, "frames": end - first}
        rest = {n: a for n, a in arrays.items() if n not in chunks.CORE}
        rest.update({n: a for n, a in self.static.items() if n not in archive.frame_singles})
        return Take(
            header=piece_header,
            pos=arrays["pos"],
            quat=arrays["quat"],
            sucker_attached=arrays["sucker_attached"],
            sucker_anchor=arrays["sucker_anchor"],
            tracks=rest,
        )

    @functools.cached_property
    def _body_owners(self) -> np.ndarray:
        """Each body's creature, worked out once (a reader asking for some bodies)."""
        return take_replay.body_owners(self.header)

    def _later(self, name: str, k: int, value: np.ndarray) -> np.ndarray:
        """The values of the items chunk `k` of `name` lacks, at the first frame holding them."""
        archive = self._archive
        assert archive is not None
        have, items = value.shape[1], archive.items[name]
        for j in range(k + 1, archive.count):
            later = archive.chunk(name, j, have)
            if later.shape[1] == items:
                return np.array(later[0, have:])
        raise TakeError(f"{self.path}: {name}: no chunk holds all {items} items")

    # -- replayed creatures --------------------------------------------------------------
    def replay_records(self) -> dict[str, np.ndarray]:
        """The per-frame replay arrays of the whole take (small: a few numbers per
        creature-frame); empty without replayed creatures."""
        if self._replay is not None:
            return self._replay
        archive = self._archive
        if archive is None or self.header.get(take_replay.KEY) is None:
            self._replay = {}
            return self._replay
        out = {
            name: np.concatenate([self._padded(name, k) for k in range(archive.count)])
            for name in take_replay.PER_FRAME
        }
        problem = take_replay.values_problem(self.header, out)
        if problem:
            raise TakeError(f"{self.path}: {problem}")
        self._replay = out
        return out

    def root_motion(self, creature: int) -> tuple[np.ndarray, np.ndarray]:
        """(xy (frames, 2), heading (frames,)) of `creature`'s ground frame (meaningful
        where it replays)."""
        records = self.replay_records()
        return records["replay_xy"][:, creature], records["replay_heading"][:, creature]

    def segments(self, creature: int) -> list[ReplaySegment]:
        """`creature`'s replayed stretches in frame order ([] when it never replays): a
        stretch ends where the kind changes or the phase does not advance evenly."""
        records = self.replay_records()
        if not records:
            return []
        clip = self.header[take_replay.KEY]["creatures"][creature]
        if clip < 0:
            return []
        kind = records["replay_kind"][:, creature].astype(np.int64)
        phase = records["replay_phase"][:, creature]
        dt = float(self.header[take_replay.KEY]["clips"][clip]["dt"])
        rate = 1.0 / (self.fps * dt)
        breaks = np.ones(len(kind), dtype=bool)
        breaks[1:] = (kind[1:] != kind[:-1]) | (np.abs(np.diff(phase) - rate) > 1e-6)
        starts = np.flatnonzero(breaks)
        ends = np.append(starts[1:], len(kind))
        return [
            ReplaySegment(int(a), int(b), int(clip), int(kind[a]), float(phase[a]), rate)
            for a, b in zip(starts.tolist(), ends.tolist(), strict=True)
            if kind[a] >= 0
        ]


_UNSOUND = (zipfile.BadZipFile, zipfile.LargeZipFile, zlib.error, EOFError, OSError,
            ValueError, NotImplementedError)  # fmt: skip  # what a broken archive raises


def _named(where: Path, error: BaseException) -> TakeError:
    """`error` as one line naming the take file."""
    if not isinstance(error, TakeError):
        return TakeError(f"{where}: not a take file ({type(error).__name__}: {error})")
    message = str(error)
    return TakeError(message if message.startswith(str(where)) else f"{where}: {message}")


def open_take(path: str | Path, max_bytes: int = MAX_TAKE_BYTES) -> TakeSource:
    """Open a take for reading a chunk at a time (`TakeSource`); raises `TakeError`."""
    return TakeSource(path, max_bytes)


def _slice(take: Take, first: int, end: int) -> Take:
    """Frames [first, end) of `take` (per-frame tracks sliced, the others whole)."""
    frames = take.frames
    tracks = {
        name: value[first:end] if _frame_axis(take, name, value, frames) else value
        for name, value in take.tracks.items()
    }
    return Take(
        header={**take.header, "frames": end - first},
        pos=take.pos[first:end],
        quat=take.quat[first:end],
        sucker_attached=take.sucker_attached[first:end],
        sucker_anchor=take.sucker_anchor[first:end],
        tracks=tracks,
    )


def _join(a: Take, b: Take) -> Take:
    """Take `a`'s frames followed by `b`'s."""
    frames = a.frames
    tracks = {
        name: np.concatenate([value, b.tracks[name]])
        if _frame_axis(a, name, value, frames)
        else value
        for name, value in a.tracks.items()
    }
    return Take(
        header={**a.header, "frames": a.frames + b.frames},
        pos=np.concatenate([a.pos, b.pos]),
        quat=np.concatenate([a.quat, b.quat]),
        sucker_attached=np.concatenate([a.sucker_attached, b.sucker_attached]),
        sucker_anchor=np.concatenate([a.sucker_anchor, b.sucker_anchor]),
        tracks=tracks,
    )


def _frame_axis(take: Take, name: str, value: np.ndarray, frames: int) -> bool:
    """Whether track array `name` has a frames axis (its first)."""
    return name in frame_arrays(take.header) and value.ndim > 0 and len(value) == frames
