"""lod_replay: kinematic creatures one frame along their way, replaying gait clips.

Reads: the physics roster's tiers, each kinematic creature's morphology clips and the
plugins' travel targets (`Plugin.travel_targets`). Writes: the kinematic creatures'
body poses, straight into the Transform store (their batch rows say so, `Batch.show`:
`physics_sync` copies only the stepped creatures' poses). Registers its replay with the level of
detail when it joins a world, so demotions to KINEMATIC become possible
(`ecs_tentacles.clips.replay`; on terrain the clips are draped over the heightfield).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ecs_tentacles.clips.replay import ClipReplay
from ecs_tentacles.system import System

if TYPE_CHECKING:
    from ecs_tentacles.host import Host
    from ecs_tentacles.roster_change import RosterChange


class LodReplay(System):
    name = "lod_replay"
    stage = "physics"
    after = ("physics",)
    reads = ("physics",)
    writes = ("physics",)
    calls_hooks = True  # the TravelTargets entries

    def setup(self, world: Host) -> None:
        self.replay = ClipReplay(world)
        world.physics.lod.replay = self.replay

    def roster_changed(self, world: Host, change: RosterChange) -> None:
        self.replay.roster_changed(change)

    def process(self, world: Host, dt: float) -> None:
        self.replay.advance(world, dt)
