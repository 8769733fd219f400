"""suckers: grab and let go.

* attach: a tentacle in its attach action grabs with its tip sucker once the sucker
  touches the ground, a slope, a wall or any obstacle (within ATTACH_HEIGHT of the
  world's `Ground`); the anchor is where the sucker is now.
* release on command: when the tentacle's action no longer grips (detach, settle,
  idle, ...).
* release on stretch: the sucker is pulled farther than the creature's
  `release_stretch` from its anchor (the elastic energy of the hold is too high).
* release on reach: the tentacle's base is farther from the anchor than
  `release_reach` tentacle lengths, so a creature never drags a sucker behind it.
* release on replay: the level of detail replays the creature (KINEMATIC, as the last
  frame decided): nothing of it is simulated, so it grips nothing, and a promoted
  creature starts free instead of yanked toward an anchor left behind. Replayed
  creatures never attach; their suckers cost nothing a frame.
Each change fires `sucker_attached` / `sucker_released` (with the reason).

Reads: locomotion's stores (action; release thresholds), TentacleStore (tip_sucker,
length, base, creature), Sucker store, Transform store, the Ground, the physics' tiers.
Writes: Sucker store (attached, anchor).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.ground import ground_of
from ecs_tentacles.locomotion.actions import GRIPPING, Kind
from ecs_tentacles.locomotion.grip import attach, release, sucker_points
from ecs_tentacles.locomotion.stores import LocomotionStores
from ecs_tentacles.numeric.optional_kernels import OptionalKernels
from ecs_tentacles.system import System

if TYPE_CHECKING:
    from ecs_tentacles.host import Host

ATTACH_HEIGHT = 0.004  # metres above the ground a sucker may be and still grab
ATTACH = int(Kind.ATTACH)
REASONS = ("replayed", "command", "stretch", "reach")  # in the order they are tested
KERNELS = OptionalKernels("ecs_tentacles.locomotion.sucker_kernels", "ECS_TENTACLES_SUCKERS")


class Suckers(System):
    name = "suckers"
    stage = "act"
    after = ("motor_targets",)
    reads = (
        "locomotion.tentacles.action",
        "locomotion.creatures.release_stretch",
        "locomotion.creatures.release_reach",
        "tentacles",
        "transforms",
        "suckers",
    )
    writes = ("suckers.attached", "suckers.anchor")

    def process(self, world: Host, dt: float) -> None:
        s, t = world.suckers, world.tentacles
        loco = world.resource(LocomotionStores)
        action, c = loco.tentacles.action, loco.creatures
        if not len(s) or not len(t):
            return
        attached = s.attached
        tip = t.tip_sucker
        kinematic = world.physics.kinematic_creatures(len(world.creatures))
        replayed = kinematic[t.creature_row]
        reaching = np.flatnonzero((action == ATTACH) & ~replayed)
        if len(reaching):
            rows = tip[reaching]
            rows = rows[~attached[rows]]
            low = ground_of(world).distance(sucker_points(world, rows)) <= ATTACH_HEIGHT
            for row in rows[low]:
                attach(world, int(s.entity[row]))

        held = np.flatnonzero(attached)
        if not len(held):
            return
        fast = KERNELS.get()
        if fast is not None:  # the same reasons in one pass
            reasons = fast.release_reasons(
                held, s.tentacle_row, t.creature_row, action, GRIPPING, tip, kinematic,
                s.link_row, s.offset, world.transforms.pos, world.transforms.quat, s.anchor,
                t.base_row, c.release_stretch, c.release_reach, t.length,
            )  # fmt: skip
            for at in np.flatnonzero(reasons)[np.argsort(reasons[reasons > 0], kind="stable")]:
                release(world, int(s.entity[held[at]]), REASONS[reasons[at] - 1])
            return
        tentacle = s.tentacle_row[held]
        creature = t.creature_row[tentacle]
        anchor = s.anchor[held]
        holding = GRIPPING[action[tentacle]] & (tip[tentacle] == held)
        stretch = np.linalg.norm(sucker_points(world, held) - anchor, axis=1)
        base = world.transforms.pos[t.base_row[tentacle], :2]
        reach = np.linalg.norm(base - anchor[:, :2], axis=1)
        reasons = (
            ("replayed", replayed[tentacle]),
            ("command", ~holding),
            ("stretch", stretch > c.release_stretch[creature]),
            ("reach", reach > c.release_reach[creature] * t.length[tentacle]),
        )
        for reason, mask in reasons:
            for row in held[mask]:
                if attached[row]:  # a sucker is released once, for the first reason
                    release(world, int(s.entity[row]), reason)
