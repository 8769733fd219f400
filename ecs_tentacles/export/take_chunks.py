"""A take in memory read as the streaming exporters read a take: chunks of frames.

    source = TakeChunks(take)                 # or a take file opened for streaming
    for first, chunk in source.chunks():      # chunk: a `Take` of frames [first, first + n)
        ...

`TakeChunks` offers what the streaming writers use of a take source: `header`, `frames`,
`fps`, `static` (the arrays without a frames axis, by file name) and `chunks()`. A
take held in memory replays nothing (`segments` is empty for every creature): each of
its creatures' bodies is in `pos` and `quat` at every frame.

Reads the `Take` it is given; writes nothing. A chunk's arrays are views of the take's
(nothing is copied); `frame_slice` makes one.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np

from ecs_tentacles.take import Take
from ecs_tentacles.take import roster as take_roster

if TYPE_CHECKING:
    from ecs_tentacles.take.stream import ReplaySegment

CHUNK_BYTES = 32 * 1024**2  # body poses (float32 pos + quat) a chunk holds, about


def per_frame(take: Take) -> list[str]:
    """The take's track arrays with a frames axis (file names): the points tracks' live
    flags, the curves tracks' points and widths, the roster's visibility."""
    names: list[str] = []
    for track in take.track_list():
        names += track.arrays[1:] if track.kind == "points" else list(track.arrays)
    names.append(take_roster.ARRAY)
    return [name for name in names if name in take.tracks]


def frame_slice(take: Take, first: int, end: int) -> Take:
    """The take's frames [first, end) as a take (views; `header["frames"]` says how many)."""
    moving = set(per_frame(take))
    tracks = {k: v[first:end] if k in moving else v for k, v in take.tracks.items()}
    header = {**take.header, "frames": end - first}
    return Take(
        header,
        take.pos[first:end],
        take.quat[first:end],
        take.sucker_attached[first:end],
        take.sucker_anchor[first:end],
        tracks,
    )


def chunk_frames(bodies: int, budget: int = CHUNK_BYTES) -> int:
    """Frames a chunk of a take of `bodies` bodies holds: about `budget` bytes of poses."""
    return max(1, budget // max(1, 28 * bodies))


class ChunkSource(Protocol):
    """What the streaming writers read of a take: `TakeChunks` (a take in memory) and
    `ecs_tentacles.take.stream.TakeSource` (a take file, versions 1 to 3)."""

    @property
    def header(self) -> dict[str, Any]: ...
    @property
    def frames(self) -> int: ...
    @property
    def fps(self) -> float: ...
    @property
    def static(self) -> dict[str, np.ndarray]: ...

    def chunks(
        self, *, bodies: np.ndarray | None = None, whole: np.ndarray | None = None
    ) -> Iterator[tuple[int, Take]]:
        """Every chunk, in order; `bodies` and `whole`: what the reader needs posed of a
        replayed creature (`TakeSource.chunks`); a source may pose more."""
        ...

    def segments(self, creature: int) -> list[ReplaySegment]: ...
    def clip_pose(self, clip: int) -> np.ndarray: ...
    def root_motion(self, creature: int) -> tuple[np.ndarray, np.ndarray]: ...


class TakeChunks:
    """A `Take` in memory as a stream of chunks of `chunk` frames (default: `chunk_frames`)."""

    def __init__(self, take: Take, chunk: int | None = None) -> None:
        self.take = take
        self.chunk = chunk or chunk_frames(len(take.header["bodies"]))

    @property
    def header(self) -> dict[str, Any]:
        """The take's header (its `frames` is the whole take's)."""
        return self.take.header

    @property
    def frames(self) -> int:
        """Frames in the whole take."""
        return self.take.frames

    @property
    def fps(self) -> float:
        """Frames per second."""
        return self.take.fps

    @property
    def static(self) -> dict[str, np.ndarray]:
        """The arrays without a frames axis, by file name (goal positions, the ground)."""
        moving = set(per_frame(self.take))
        return {k: v for k, v in self.take.tracks.items() if k not in moving}

    def chunks(
        self, *, bodies: np.ndarray | None = None, whole: np.ndarray | None = None
    ) -> Iterator[tuple[int, Take]]:
        """(first frame, the take's frames from there) for every chunk, in order (every
        body posed, whatever `bodies` and `whole` ask: a take in memory holds them)."""
        for first in range(0, self.frames, self.chunk):
            yield first, frame_slice(self.take, first, min(first + self.chunk, self.frames))

    def segments(self, creature: int) -> list[ReplaySegment]:
        """Replayed stretches of `creature`: none (a take in memory holds every pose)."""
        return []

    def clip_pose(self, clip: int) -> np.ndarray:
        """A take in memory replays no clip (`segments` is empty)."""
        raise KeyError(f"a take in memory holds every pose: no clip {clip}")

    def root_motion(self, creature: int) -> tuple[np.ndarray, np.ndarray]:
        """A take in memory replays no creature (`segments` is empty)."""
        raise KeyError(f"a take in memory holds every pose: creature {creature} replays nothing")
