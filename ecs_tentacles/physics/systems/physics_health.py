"""physics_health: every creature's physics checked after the step; failures recovered.

Reads: every batch's step results (warnings, velocities, deepest contact), the Transform
store (this frame's poses against last frame's, for speeds and non-finite poses),
the Sucker store (attached, entity: which suckers a failing creature holds).
Writes: the failing creature's state row (restored to its last good state) and its
Transform rows (pos, quat), Sucker store (attached: its suckers released), events
`creature_recovered` / `creature_frozen` / `sucker_released`. Runs right after
`physics_sync`, before any system that reads poses, so no system sees a blown-up
pose (`ecs_tentacles.physics.health`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ecs_tentacles.system import System

if TYPE_CHECKING:
    from ecs_tentacles.host import Host


class PhysicsHealth(System):
    name = "physics_health"
    stage = "sync"
    after = ("physics_sync",)
    reads = ("physics", "transforms.pos", "suckers.attached", "suckers.entity")
    writes = ("physics", "transforms.pos", "transforms.quat", "suckers.attached")

    def process(self, world: Host, dt: float) -> None:
        physics = world.physics
        physics.health.check(world, physics.time)
