"""lod_replay: kinematic creatures one frame along their way, replaying gait clips.

Reads: the physics roster's tiers, each kinematic creature's morphology clips and the
plugins' travel targets (`Plugin.travel_targets`). Writes: the kinematic creatures'
body poses in their physics batch (copied into the Transform store by
`physics_sync`, like every other creature's). Registers its replay with the level of
detail when it joins a world, so demotions to KINEMATIC become possible
(`ecs_tentacles.lod.replay`). The clips are recorded and replayed on the plane z = 0:
on terrain (a `Ground` that is not flat) the replay is not registered, and creatures
past the budgets run REDUCED instead of floating over or sinking into the relief.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ecs_tentacles.ground import ground_of
from ecs_tentacles.lod.replay import ClipReplay
from ecs_tentacles.system import System

if TYPE_CHECKING:
    from ecs_tentacles.host import Host


class LodReplay(System):
    name = "lod_replay"
    stage = "physics"
    after = ("physics",)
    reads = ("physics",)
    writes = ("physics",)
    calls_hooks = True  # travel_targets

    def setup(self, world: Host) -> None:
        self.replay: ClipReplay | None = None
        if ground_of(world).flat:
            self.replay = ClipReplay(world)
            world.physics.lod.replay = self.replay

    def process(self, world: Host, dt: float) -> None:
        if self.replay is not None:
            self.replay.advance(world, dt)
