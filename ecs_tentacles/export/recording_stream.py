"""A streamed take's side of the recorder: frames handed to a `TakeWriter` in chunks.

`StreamedFrames` is a base of `ecs_tentacles.export.recording.TakeRecorder`: with a
writer, the recorder's frame arrays hold one chunk; `_flush` hands it to the writer
(the replay records blanked as the file stores them, the curves tracks recording by
then chunked too), `finish_stream` writes the last frames and the header. It reads the
recorder's arrays and tracks and writes nothing but to the writer.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import TYPE_CHECKING, Any

import numpy as np

from ecs_tentacles.export.frame_arrays import resized_frames
from ecs_tentacles.export.track_recording import CurvesTrack, PointsTrack
from ecs_tentacles.take import TakeError, chunks
from ecs_tentacles.take import replay as take_replay
from ecs_tentacles.take.entries import data_problem

if TYPE_CHECKING:
    from ecs_tentacles.take.writer import TakeWriter


class StreamedFrames(ABC):
    """Chunks of frames to the writer, and the stream's end (the recorder's arrays)."""

    writer: TakeWriter | None
    header: dict[str, Any]
    tracks: list[PointsTrack | CurvesTrack]
    count: int
    _base: int  # frames handed to the writer
    _finished: bool
    _pos: np.ndarray
    _quat: np.ndarray
    _attached: np.ndarray
    _anchor: np.ndarray
    _replayed: dict[str, np.ndarray]
    _flushed_last: dict[str, np.ndarray]  # the last frame handed over
    _chunked_curves: list[CurvesTrack] | None  # decided at the first flush

    @abstractmethod
    def _header_and_tracks(
        self, n: int, copy: bool
    ) -> tuple[dict[str, Any], dict[str, np.ndarray]]:
        """The take's header and tracks of its first `n` frames (`TakeRecorder`'s)."""

    def _size_chunks(self) -> None:
        """Frames per chunk from the first frame's bytes of every chunked array (the
        curves tracks sampled by now among them), as `Take.save` counts them."""
        assert self.writer is not None
        frame = sum(a[:1].nbytes for a in self._chunk_arrays(1).values())
        for track in self.tracks:
            if isinstance(track, CurvesTrack):
                frame += sum(a[:1].nbytes for a in track.arrays(1, copy=False).values())
        self.writer.chunk_frames = per = chunks.chunk_frames(frame)
        for name in ("_pos", "_quat", "_attached", "_anchor"):
            setattr(self, name, resized_frames(getattr(self, name), per))
        self._replayed = {k: resized_frames(v, per) for k, v in self._replayed.items()}

    def _before(self, name: str, i: int) -> np.ndarray | None:
        """Frame `i - 1` of chunked array `name` (`_pos`, ...): in the array, or the last
        frame handed to the writer when `i` starts a chunk; None before the first."""
        if i:
            return np.asarray(getattr(self, f"_{name}")[i - 1])
        return self._flushed_last.get(name)

    def _chunk_arrays(self, frames: int) -> dict[str, np.ndarray]:
        """The chunked arrays' first `frames` frames, by file name."""
        out = {
            "pos": self._pos[:frames],
            "quat": self._quat[:frames],
            "sucker_attached": self._attached[:frames],
            "sucker_anchor": self._anchor[:frames],
        }
        out.update({name: value[:frames] for name, value in self._replayed.items()})
        return out

    def _flush(self) -> None:
        """Hand the frames held to the writer (streamed recording). The first time, the
        curves tracks recording by then are chunked too (`header["chunked"]`)."""
        assert self.writer is not None
        held = self.count - self._base
        if not held:
            return
        if self._chunked_curves is None:
            self._chunked_curves = [t for t in self.tracks if isinstance(t, CurvesTrack)
                                    and t.flush(self._base) is not None]  # fmt: skip
            curves = [a for t in self._chunked_curves for a in t.track.arrays]
            self.header["chunked"] = [*self._chunk_arrays(0), *curves]
            points = [t.track.arrays[0] for t in self._chunked_curves]
            self.writer.quantised = dict.fromkeys(points, chunks.STEP)  # as `Take.save` does
        arrays = self._chunk_arrays(held)
        for track in self._chunked_curves:
            arrays.update(track.flush(self.count) or {})
        numbers = {k: v for k, v in arrays.items() if not k.startswith("replay_")}
        problem = data_problem(numbers, [t.track for t in self._chunked_curves], self._base)
        if problem:  # a plugin's NaN: nobody could read the take
            raise TakeError(f"{self.writer.path}: cannot write this take: {problem}")
        # a creature gone keeps its last pose: remembered across the chunk boundary
        self._flushed_last = {
            name: getattr(self, f"_{name}")[held - 1].copy() for name in ("pos", "quat", "anchor")
        }
        self.writer.add_frames(take_replay.blanked(self.header, arrays, in_place=True))
        self._base = self.count

    def finish_stream(self) -> dict[str, Any]:
        """End a streamed recording: the last frames, the arrays without chunks and the
        header go to the writer (its file is renamed into place when its block ends);
        returns the header as written."""
        assert self.writer is not None, "finish_stream() ends a streamed recording"
        self._flush()
        self._finished = True
        header, tracks = self._header_and_tracks(self.count, copy=False)
        self.writer.finish(header, tracks)
        return {**header, "frames": self.writer.frames, "chunk_frames": self.writer.chunk_frames}
