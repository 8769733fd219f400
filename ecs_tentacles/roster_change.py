"""`RosterChange`: what plugins and systems are told when a creature comes or goes.

`World.spawn` and `World.despawn` (`ecs_tentacles.creatures.spawning`) call every plugin's and
every system's `roster_changed(world, change)` once the stores and the physics have
changed, so anything kept beside the stores (arrays by row, lists by creature, GPU
instance tables) can follow. Store columns need no hook: they move with their store.

    def roster_changed(self, world, change):
        if change.moved:                       # a despawn: rows moved up
            keep = change.moved["tentacles"] >= 0
            self.per_tentacle = self.per_tentacle[keep]
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class RosterChange:
    """One creature spawned or despawned.

    `creature` is its entity and `spawned` says which. For a despawn, `moved` maps each
    store name (`world.stores`) whose rows were removed to every old row's new row
    (-1: removed with the creature); rows after the removed ones moved up, keeping
    their order. For a spawn, `added` maps store names to the rows appended at their
    ends (no row moved). `index` is its place in the physics' per-creature arrays
    (`PhysicsBackend.roster`): appended last, or removed (later ones move down one).
    """

    creature: int
    spawned: bool
    index: int  # its place in the physics' per-creature arrays (appended, or removed)
    moved: dict[str, np.ndarray] = field(default_factory=dict)
    added: dict[str, np.ndarray] = field(default_factory=dict)

    def follow(self, array: np.ndarray, store: str, new: np.ndarray | float = 0.0) -> np.ndarray:
        """`array` (one entry per row of `store`) after the change: the removed rows'
        entries dropped, or entries `new` appended for the rows added."""
        if not self.spawned:
            return array[self.kept(store)]
        count = len(self.added.get(store, ()))
        if not count:
            return array
        extra = np.empty((count, *array.shape[1:]), dtype=array.dtype)
        extra[...] = new
        return np.concatenate([array, extra])

    def follow_creatures(self, array: np.ndarray, new: np.ndarray | float = 0.0) -> np.ndarray:
        """`array` (one entry per creature of the physics, roster order) after the change."""
        if not self.spawned:
            return np.delete(array, self.index, axis=0)
        extra = np.empty((1, *array.shape[1:]), dtype=array.dtype)
        extra[...] = new
        return np.concatenate([array, extra])

    def kept(self, store: str) -> np.ndarray | slice:
        """Which old rows of `store` are left: a bool mask after a despawn, else all."""
        moved = self.moved.get(store)
        return slice(None) if moved is None else moved >= 0
