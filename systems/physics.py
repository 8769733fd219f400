"""physics: steps MuJoCo one frame.

Reads: Motor store (target, strength, damping, max_torque), Sucker store (attached,
anchor), Transform store (where other creatures are). Writes, in every physics group:
MjData (ctrl, eq_active, contact proxies' mocap poses), MjModel servo gains, sucker
anchors and proxy sizes; puts still, idle creatures to sleep (`physics.sleep`) and
wakes the others; then advances `world.settings.substeps` steps, the awake groups in
parallel. Systems that override
`System.substep` run before every substep, in schedule order.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ecs_tentacles.system import System

if TYPE_CHECKING:
    from ecs_tentacles.world import World


class Physics(System):
    name = "physics"

    def process(self, world: World, dt: float) -> None:
        backend = world.physics
        backend.write_controls(world.motors)
        backend.write_suckers(world.suckers)
        backend.proxies.update(world.transforms)
        backend.sleep.update(world)
        hooks = world.schedule.substep_systems()
        if not hooks:
            backend.step(world.settings.substeps)
            return
        substep_dt = world.settings.substep_dt

        def before_substep(index: int) -> None:
            for system in hooks:
                system.substep(world, index, substep_dt)

        backend.step(world.settings.substeps, before_substep)
