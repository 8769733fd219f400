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

from ecs_tentacles.system import System, SystemFailure

if TYPE_CHECKING:
    from ecs_tentacles.world import World


PROXY_ROUNDS = 4  # parts a frame is stepped in while creatures touch (proxies catch up)


class Physics(System):
    name = "physics"
    stage = "physics"
    reads = (
        "motors.target",
        "motors.gain",
        "motors.strength",
        "motors.damping",
        "motors.max_torque",
        "suckers.attached",
        "suckers.anchor",
        "transforms.pos",
        "transforms.quat",
        "locomotion.creatures.has_goal",  # sleep: a creature with a goal stays awake
    )
    writes = ("physics",)

    def process(self, world: World, dt: float) -> None:
        backend = world.physics
        backend.write_controls(world.motors)
        backend.write_suckers(world.suckers)
        backend.proxies.update(world.transforms)
        backend.sleep.update(world)
        hooks = world.schedule.substep_systems()
        if not hooks:
            proxies = backend.proxies
            if not proxies.in_use:
                backend.step(world.settings.substeps)
                return
            # creatures near each other: step the frame in parts, their proxies following
            transforms = world.transforms
            backend.step(
                world.settings.substeps,
                rounds=PROXY_ROUNDS,
                between=lambda: proxies.refresh(transforms),
            )
            return
        substep_dt = world.settings.substep_dt

        def before_substep(index: int) -> None:
            for system in hooks:
                try:
                    system.substep(world, index, substep_dt)
                except Exception as error:  # name the hook's system, not physics
                    label = world.schedule.label(system)
                    raise SystemFailure(system, label, world.frame, error) from error

        backend.step(world.settings.substeps, before_substep)
