"""physics: steps MuJoCo one frame.

Reads: Motor store (target, strength, damping, max_torque, gain), Sucker store
(attached, anchor), Transform store (pos, quat: where other creatures are), and which
creatures the plugins want to move (`Plugin.wants_motion`). Writes, in every batch
of the physics (`physics.batch`): each creature's state row (ctrl, sucker switches,
contact proxies' poses) and overlay (servo gains, torque limits, sucker anchors, proxy
sizes); decides each creature's level of detail (`physics.lod`: promotions start
from the shown pose); puts still, idle creatures to sleep (`physics.sleep`) and wakes
the others; then advances `world.settings.substeps` steps, the awake creatures on the stepping
threads. Systems that override `System.substep` run before every substep, in
schedule order.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.physics.registries import MotionWants
from ecs_tentacles.system import System, SystemFailure

if TYPE_CHECKING:
    from ecs_tentacles.host import Host


PROXY_ROUNDS = 4  # parts a frame is stepped in while creatures touch (proxies catch up)


class Physics(System):
    name = "physics"
    stage = "physics"
    reads = (
        "motors.target",
        "motors.strength",
        "motors.damping",
        "motors.max_torque",
        "motors.gain",
        "suckers.attached",
        "suckers.anchor",
        "transforms.pos",
        "transforms.quat",
    )
    writes = ("physics",)
    calls_hooks = True  # the MotionWants entries

    def process(self, world: Host, dt: float) -> None:
        backend = world.physics
        backend.lod.update(world)  # first: a promoted creature's servos start soft
        backend.place_stepped()  # the rows stepped from now on that the build only showed
        backend.write_controls(world.motors)
        backend.write_suckers(world.suckers)
        backend.proxies.update(world.transforms, world.frame)
        backend.sleep.update(world, wanted_motion(world))
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
                between=lambda ready: proxies.refresh(transforms, ready),
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


def wanted_motion(world: Host) -> np.ndarray | None:
    """Creatures (bool per CreatureStore row) some plugin wants to move, or None for none.

    The answers of every `MotionWants` entry (`ecs_tentacles.physics.registries`), or-ed;
    one array operation per entry that answers.
    """
    wanted: np.ndarray | None = None
    for wants in world.registry(MotionWants):
        answer = wants(world)
        if answer is not None:
            wanted = answer if wanted is None else wanted | answer
    return wanted
