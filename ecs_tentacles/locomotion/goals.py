"""Goals and paths: the API the sandbox, scripts and the `goals` system use.

A goal is an entity with a `Goal` component (position, radius, owner, order in its
owner's path). A creature has no goal, one, or an ordered path; the first is
current and is mirrored into the CreatureStore (`has_goal`, `goal`, `goal_radius`)
for the vectorised systems. Changes happen on calls (clicks, scripts, a goal
reached), never per frame.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import esper
import numpy as np

from ecs_tentacles.components import Creature
from ecs_tentacles.ground import ground_of
from ecs_tentacles.locomotion.components import Goal
from ecs_tentacles.locomotion.events import GoalReached
from ecs_tentacles.locomotion.stores import LocomotionStores

if TYPE_CHECKING:
    from ecs_tentacles.host import Host

DEFAULT_RADIUS = 0.3
# what a system that sets, appends, reaches or removes goals through the GoalBook writes
# (its `writes`): the goal entities and the current goal's columns (`GoalBook._sync`)
GOAL_WRITES = (
    "goals",
    "locomotion.creatures.goal",
    "locomotion.creatures.has_goal",
    "locomotion.creatures.goal_radius",
)


@dataclass(frozen=True)
class GoalTable:
    """Every goal at one moment: its entity, owner, order in the owner's path, position
    (n, 3) and radius, in the owners' path order."""

    keys: np.ndarray
    owners: np.ndarray
    orders: np.ndarray
    positions: np.ndarray
    radii: np.ndarray


class GoalBook:
    """Each creature's ordered path of goal entities."""

    provided_by = "locomotion"  # the plugin that makes it (named by `world.resource` errors)

    def __init__(self, world: Host):
        self._world = world
        self._paths: dict[int, list[int]] = {}
        self.version = 0  # bumped on every change, so views can cache what they drew
        self._table: tuple[int, GoalTable] | None = None  # (version, every goal)

    def path(self, creature: int) -> list[int]:
        """The creature's goal entities in order (a copy)."""
        return list(self._paths.get(creature, []))

    def current(self, creature: int) -> int | None:
        """The goal the creature is heading for, or None."""
        path = self._paths.get(creature)
        return path[0] if path else None

    def positions(self, creature: int) -> np.ndarray:
        """(n, 3) positions of the creature's path, in order."""
        goals = [self._world.component(g, Goal).position for g in self._paths.get(creature, [])]
        return np.array(goals).reshape(-1, 3)

    def table(self) -> GoalTable:
        """Every goal of every path as arrays (the goals track samples it each frame):
        built when the book has changed since it was last asked, shared until then."""
        if self._table is None or self._table[0] != self.version:
            keys = [goal for path in self._paths.values() for goal in path]
            goals = [self._world.component(key, Goal) for key in keys]
            table = GoalTable(
                keys=np.array(keys, dtype=np.int64),
                owners=np.array([g.owner for g in goals], dtype=np.int64),
                orders=np.array([g.order for g in goals], dtype=np.int64),
                positions=np.array([g.position for g in goals], dtype=np.float64).reshape(-1, 3),
                radii=np.array([g.radius for g in goals], dtype=np.float64),
            )
            self._table = (self.version, table)
        return self._table[1]

    def set(self, creature: int, position: Sequence[float], radius: float = DEFAULT_RADIUS) -> int:
        """Replace the creature's path with one goal; return the goal entity.

        A bad position or radius raises ValueError and leaves the old path alone.
        """
        point = self._checked(creature, position, radius)
        self.clear(creature)
        return self._append(creature, point, radius)

    def append(
        self, creature: int, position: Sequence[float], radius: float = DEFAULT_RADIUS
    ) -> int:
        """Add a goal at the end of the creature's path; return the goal entity."""
        return self._append(creature, self._checked(creature, position, radius), radius)

    def _checked(self, creature: int, position: Sequence[float], radius: float) -> np.ndarray:
        values = np.asarray(position, dtype=np.float64)
        if values.shape not in ((2,), (3,)) or not np.isfinite(values).all():
            raise ValueError(f"goal position must be 2 or 3 finite numbers, got {list(position)}")
        if not radius > 0:
            raise ValueError(f"goal radius must be > 0, got {radius}")
        self._world.component(creature, Creature)  # raises KeyError for a non-creature
        point = np.zeros(3)
        point[: len(values)] = values
        if len(values) == 2:  # on the topmost surface under it (the plane: z = 0)
            point[2] = ground_of(self._world).surface(values)[0]
        return point

    def _append(self, creature: int, point: np.ndarray, radius: float) -> int:
        path = self._paths.setdefault(creature, [])
        goal = self._world.create_entity(Goal(creature, len(path), point, float(radius)))
        path.append(goal)
        self.version += 1
        if len(path) == 1:  # the goals before keep their order and the current one
            self._sync(creature)
        return goal

    def remove(self, goal: int) -> None:
        """Delete a goal wherever it is in its owner's path (the goals after it move up)."""
        owner = self._world.component(goal, Goal).owner
        path = self._paths[owner]
        index = path.index(goal)
        del path[index]
        self._world.activate()
        esper.delete_entity(goal, immediate=True)
        for order in range(index, len(path)):
            self._world.component(path[order], Goal).order = order
        self.version += 1
        if index == 0:
            self._sync(owner)

    def clear(self, creature: int) -> None:
        """Delete all of the creature's goals."""
        path = self._paths.get(creature)
        if not path:
            return
        self._world.activate()
        for goal in path[:-1]:
            esper.delete_entity(goal, immediate=True)
        # the store keeps the last goal's place with has_goal off, as removing the goals
        # one by one left it (snapshots of the columns stay the same)
        del path[:-1]
        self._sync(creature)
        esper.delete_entity(path.pop(), immediate=True)
        self.version += 1
        self._sync(creature)

    def forget(self, creature: int) -> None:
        """The creature is being despawned: delete its goals and its path."""
        self.clear(creature)
        self._paths.pop(creature, None)

    def reach(self, creature: int) -> None:
        """The current goal was reached: remove it, fire `goal_reached`, move to the next."""
        goal = self.current(creature)
        if goal is None:
            return
        position = self._world.component(goal, Goal).position.copy()
        self.remove(goal)
        self._world.events.emit(GoalReached(self._world, creature, goal, position))

    def _sync(self, creature: int) -> None:
        """Mirror the creature's current goal into the CreatureStore (a goal's `order` is
        kept by whoever changes the path: every call is linear in the goals it touches)."""
        path = self._paths.get(creature, [])
        row = self._world.component(creature, Creature).row
        store = self._world.resource(LocomotionStores).creatures
        store.has_goal[row] = bool(path)
        if path:
            first = self._world.component(path[0], Goal)
            store.goal[row] = first.position
            store.goal_radius[row] = first.radius
