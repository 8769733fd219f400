"""goals: a creature whose mantle enters its current goal's radius reaches it.

Reads: locomotion's creature store (has_goal, goal, goal_radius), CreatureStore
(mantle_row, entity), Transform store.
Writes: through `world.resource(GoalBook).reach` (removes the goal entity, makes the next goal of
the path current, fires `goal_reached`). Distances are measured in the ground plane.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.behaviour import ARRIVALS
from ecs_tentacles.locomotion.goals import GOAL_WRITES, GoalBook
from ecs_tentacles.locomotion.stores import LocomotionStores
from ecs_tentacles.numeric.optional_kernels import OptionalKernels
from ecs_tentacles.system import System

if TYPE_CHECKING:
    from ecs_tentacles.host import Host

KERNELS = OptionalKernels("ecs_tentacles.locomotion.goal_kernels", "ECS_TENTACLES_GOALS")


class Goals(System):
    name = "goals"
    stage = "decide"
    sets = (ARRIVALS,)
    reads = (
        "transforms.pos",
        "goals",
        "creatures.mantle_row",
        "creatures.entity",
        "locomotion.creatures.has_goal",
        "locomotion.creatures.goal",
        "locomotion.creatures.goal_radius",
    )
    writes = GOAL_WRITES

    def process(self, world: Host, dt: float) -> None:
        gaits = world.resource(LocomotionStores).creatures
        if not gaits.has_goal.any():
            return
        creatures = world.creatures
        fast = KERNELS.get()
        if fast is not None:  # the same creatures in one pass
            reached = fast.reached(world.transforms.pos, creatures.mantle_row, gaits.goal,
                                   gaits.goal_radius, gaits.has_goal)  # fmt: skip
        else:
            offset = world.transforms.pos[creatures.mantle_row, :2] - gaits.goal[:, :2]
            distance_sq = np.einsum("ij,ij->i", offset, offset)
            reached = np.flatnonzero(gaits.has_goal & (distance_sq <= gaits.goal_radius**2))
        for row in reached:
            world.resource(GoalBook).reach(int(creatures.entity[row]))
