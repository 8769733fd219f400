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
from ecs_tentacles.system import System

if TYPE_CHECKING:
    from ecs_tentacles.host import Host


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
        offset = world.transforms.pos[creatures.mantle_row, :2] - gaits.goal[:, :2]
        distance_sq = np.einsum("ij,ij->i", offset, offset)
        reached = gaits.has_goal & (distance_sq <= gaits.goal_radius**2)
        for row in np.flatnonzero(reached):
            world.resource(GoalBook).reach(int(creatures.entity[row]))
