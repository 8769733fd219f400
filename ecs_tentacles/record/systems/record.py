"""record: appends the frame to a take (optional; `ecs-tentacles bake` adds it).

Reads: Transform store (every mantle and link), Sucker store (attached, anchor),
and whatever the plugins' take tracks sample (`TakeTracks` entries: goals, fur
guide curves). Writes: its `TakeRecorder`'s arrays; before the first frame only,
whatever the plugins' `RecordingStarts` entries write (the fur rig's output buffers,
which the rig rewrites every frame).

Runs in stage output, after everything else of the frame. It records the
pose it finds when it joins the world (take frame 0; the plugins prepare it, e.g.
fur guides are posed if no frame has run yet), then every `every`-th frame, so a
take at 30 fps of a 60 fps world has `every=2`. The record plugin
(`ecs_tentacles.record.plugin`) adds it.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, TypedDict, Unpack

from ecs_tentacles.export.recording import TakeRecorder, before_recording
from ecs_tentacles.system import System
from ecs_tentacles.take import Take

if TYPE_CHECKING:
    from ecs_tentacles.host import Host
    from ecs_tentacles.roster_change import RosterChange
    from ecs_tentacles.take.registries import TrackSource
    from ecs_tentacles.take.writer import TakeWriter


class RecorderOptions(TypedDict, total=False):
    """`TakeRecorder`'s keywords a `Record` passes on (its `fps` is the world's / every)."""

    scene_sha256: str | None
    capacity: int
    tracks: Sequence[TrackSource]
    writer: TakeWriter | None


class Record(System):
    """Record the world into a take; `record.take()` returns it (`finish()`: for good)."""

    name = "record"
    calls_hooks = True  # the plugins' TakeTracks entries
    stage = "output"
    # and what the plugins' take tracks sample (their hook_reads: goals, fur guides)
    reads = ("transforms.pos", "transforms.quat", "suckers.attached", "suckers.anchor")

    def __init__(self, every: int = 1, **recorder: Unpack[RecorderOptions]):
        if every < 1:
            raise ValueError(f"every must be >= 1, got {every}")
        self.every = every
        self._options = recorder  # TakeRecorder keywords: scene_sha256, capacity, tracks, writer
        self.recorder: TakeRecorder | None = None
        self._start = 0

    def setup(self, world: Host) -> None:
        from ecs_tentacles.world import World  # a take needs the plugins' hooks and schedule

        if not isinstance(world, World):
            raise TypeError(f"record needs an ecs_tentacles World, got {type(world).__name__}")
        fps = world.settings.fps / self.every
        self.recorder = TakeRecorder(world, fps=fps, **self._options)
        before_recording(world)
        self.recorder.capture()
        self._start = world.frame

    def roster_changed(self, world: Host, change: RosterChange) -> None:
        if self.recorder is not None:  # the take's roster follows (`take.roster`)
            self.recorder.roster_changed(change)

    def process(self, world: Host, dt: float) -> None:
        recorder = self.recorder
        if recorder is None or recorder.finished:  # finish(): the world may step on
            return
        if (world.frame + 1 - self._start) % self.every == 0:
            recorder.capture()

    def take(self) -> Take:
        """The frames recorded so far (copies; recording may go on)."""
        return self._recorder().take()

    def finish(self) -> Take:
        """The frames recorded, ending the recording (no copies: `TakeRecorder.finish`)."""
        return self._recorder().finish()

    def finish_stream(self) -> dict[str, object]:
        """End a streamed recording (`TakeRecorder.finish_stream`); the header written."""
        return self._recorder().finish_stream()

    def _recorder(self) -> TakeRecorder:
        if self.recorder is None:
            raise RuntimeError("the record system has not joined a world yet")
        return self.recorder
