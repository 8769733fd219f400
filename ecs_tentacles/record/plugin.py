"""The record plugin: the run recorded into a take (`ecs-tentacles bake` adds it).

    record = RecordPlugin(every=2)        # a 30 fps take of a 60 fps world
    world.add_plugin(record)
    world.step(120)
    take = record.take()                  # a copy; record.finish(): for good, no copy

Systems: record (stage output), which captures the frame after everything else ran.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Unpack

from ecs_tentacles.plugin import Plugin
from ecs_tentacles.system import System
from ecs_tentacles.take import Take

if TYPE_CHECKING:
    from ecs_tentacles.record.systems.record import RecorderOptions


class RecordPlugin(Plugin):
    name = "record"
    description = "records every frame's poses, suckers and the plugins' take tracks into a take"

    def __init__(
        self,
        config: dict[str, object] | None = None,
        *,
        every: int = 1,
        **recorder: Unpack[RecorderOptions],
    ):
        super().__init__(config)
        from ecs_tentacles.record.systems.record import Record

        self.system = Record(every, **recorder)

    def systems(self) -> list[System]:
        return [self.system]

    def take(self) -> Take:
        """The frames recorded so far (copies; recording may go on)."""
        return self.system.take()

    def finish(self) -> Take:
        """The frames recorded, ending the recording (the take holds the recorder's
        arrays: no copies)."""
        return self.system.finish()

    def finish_stream(self) -> dict[str, object]:
        """End a recording streamed to its `writer` (a `TakeWriter`); the header written."""
        return self.system.finish_stream()
