"""The clips plugin (scene key `plugins.clips`, `lod` before): gait-clip replay for the
KINEMATIC level of detail.

The physics decides who runs at which tier (`ecs_tentacles.physics.lod`, `world.lod`);
without this plugin nobody is ever kinematic (the cheapest tier is REDUCED). With it,
the `lod_replay` system (stage physics, after the step) moves kinematic creatures with
their morphology's gait clips (`ecs_tentacles.clips.replay`), toward where the plugins
say they go (`TravelTargets` entries: the locomotion plugin's goals). Snapshots keep
the replay's state.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING

from ecs_tentacles.plugin import Plugin
from ecs_tentacles.system import System

if TYPE_CHECKING:
    from ecs_tentacles.host import Host
    from ecs_tentacles.take.tracks import TrackSize


class ClipsPlugin(Plugin):
    name = "clips"  # was "lod", which scenes still load by (the "renamed" entry points)
    build_order = 50  # a default plugin: built after fur (40), before terrain (60)
    description = "kinematic crowds: creatures far from the action replay gait clips"

    def systems(self) -> list[System]:
        from ecs_tentacles.clips.systems.replay import LodReplay

        return [LodReplay()]

    def take_sizes(self, scene: Mapping[str, object]) -> list[TrackSize]:
        """A take of a scene on flat ground records each creature's replay (kind, phase,
        place, heading: 33 bytes a frame; `ecs_tentacles.take.replay`), and each body
        plan's clips once (not counted: known only when recorded)."""
        from ecs_tentacles.take.tracks import TrackSize

        if scene.get("terrain") is not None:
            return []
        creatures = scene.get("creatures")
        count = len(creatures) if isinstance(creatures, list) else 0
        return [TrackSize("replay records", count, 33, chunked=True)] if count else []

    def snapshot(self, world: Host) -> object:
        replay = world.physics.lod.replay
        return None if replay is None else replay.state()  # type: ignore[attr-defined]

    def restore(self, world: Host, state: object) -> None:
        replay = world.physics.lod.replay
        if replay is not None and state is not None:
            replay.set_state(state)  # type: ignore[attr-defined]
