"""goals: a creature whose mantle enters its current goal's radius reaches it.

Reads: CreatureStore (has_goal, goal, goal_radius, mantle_row), Transform store.
Writes: through `world.resource(GoalBook).reach` (removes the goal entity, makes the next goal of
the path current, fires `goal_reached`). Distances are measured in the ground plane.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.locomotion.goals import GoalBook
from ecs_tentacles.system import System

if TYPE_CHECKING:
    from ecs_tentacles.host import Host


class Goals(System):
    name = "goals"
    stage = "decide"
    reads = ("transforms.pos", "goals")
    writes = ("goals", "creatures.goal", "creatures.has_goal")

    def process(self, world: Host, dt: float) -> None:
        creatures = world.creatures
        if not creatures.has_goal.any():
            return
        offset = world.transforms.pos[creatures.mantle_row, :2] - creatures.goal[:, :2]
        distance_sq = np.einsum("ij,ij->i", offset, offset)
        reached = creatures.has_goal & (distance_sq <= creatures.goal_radius**2)
        for row in np.flatnonzero(reached):
            world.resource(GoalBook).reach(int(creatures.entity[row]))
