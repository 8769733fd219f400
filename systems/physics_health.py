"""physics_health: every creature's physics checked after the step; failures recovered.

Reads: each physics group's MjData (warnings, qpos, qvel, poses, contacts), the
Transform store (last frame's poses, for speeds). Writes: the failing group's MjData
(restored to its last good state), Sucker store (its suckers released), events
`creature_recovered` / `creature_frozen`. Runs before `physics_sync`, so a blown-up
pose never reaches the store (`ecs_tentacles.physics.health`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ecs_tentacles.system import System

if TYPE_CHECKING:
    from ecs_tentacles.world import World


class PhysicsHealth(System):
    name = "physics_health"
    after = ("physics",)
    before = ("physics_sync",)

    def process(self, world: World, dt: float) -> None:
        world.physics.health.check(world)
