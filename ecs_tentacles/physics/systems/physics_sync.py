"""physics_sync: copies body poses from MuJoCo into the Transform store.

Reads: every batch's body poses after the step (`physics.batch`: xpos, xquat).
Writes: Transform store (pos, quat) of every mantle and link, one scatter per batch
and field, but those of replayed creatures (`lod_replay` wrote them there already).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ecs_tentacles.system import System

if TYPE_CHECKING:
    from ecs_tentacles.host import Host


class PhysicsSync(System):
    name = "physics_sync"
    stage = "sync"
    reads = ("physics",)
    writes = ("transforms.pos", "transforms.quat")

    def process(self, world: Host, dt: float) -> None:
        world.physics.sync(world.transforms)
