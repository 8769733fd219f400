"""Every creature of the physics, as arrays: where its state lives and how it runs.

Creatures have an index (entity order) in every array here; `batch_of` / `row_of`
say which batch (`physics.batch`) holds its state and in which row. The run-time
flags are whole arrays too, so health, sleep, proxies and level of detail decide for
every creature at once. The backend owns the roster; its parts read and write it.
"""

from __future__ import annotations

import numpy as np

from ecs_tentacles.physics.batch import Batch
from ecs_tentacles.physics.tiers import FULL, KINEMATIC


class Roster:
    """Per-creature arrays shared by the backend's parts."""

    def __init__(self, entities: np.ndarray, creature_rows: np.ndarray):
        count = len(entities)
        self.entity = np.asarray(entities, dtype=np.int64)  # creature entity per index
        self.creature_row = np.asarray(creature_rows, dtype=np.int64)  # CreatureStore row
        self.batch_of = np.zeros(count, dtype=np.int64)
        self.row_of = np.zeros(count, dtype=np.int64)
        self.batches: list[Batch] = []
        self.frozen = np.zeros(count, dtype=bool)  # after repeated failures
        self.sleeping = np.zeros(count, dtype=bool)
        self.soften = np.ones(count)  # servo gain multiplier while recovering (1 = normal)
        self.proxies_used = np.zeros(count, dtype=np.int64)  # proxies placed last frame
        self.tier = np.full(count, FULL, dtype=np.int8)  # level of detail (`physics.tiers`)

    def __len__(self) -> int:
        return len(self.entity)

    def add(self, batch: Batch, indices: list[int]) -> None:
        """`batch` holds the creatures `indices`, in that row order."""
        batch.members[:] = indices
        self.batch_of[indices] = batch.index
        self.row_of[indices] = np.arange(len(indices))
        self.batches.append(batch)

    PER_CREATURE = ("entity", "creature_row", "batch_of", "row_of", "frozen", "sleeping",
                    "soften", "proxies_used", "tier")  # fmt: skip

    def append(self, entity: int, creature_row: int, batch: Batch, row: int) -> int:
        """One more creature (full, awake), at the end; its index."""
        values = (entity, creature_row, batch.index, row, False, False, 1.0, 0, FULL)
        for name, value in zip(self.PER_CREATURE, values, strict=True):
            array = getattr(self, name)
            setattr(self, name, np.append(array, np.array([value], dtype=array.dtype)))
        return len(self) - 1

    def remove(self, index: int) -> None:
        """Take creature `index` out (its batch row too); later indices move down one."""
        batch, row = self.locate(index)
        batch.remove(row)
        for name in self.PER_CREATURE:
            setattr(self, name, np.delete(getattr(self, name), index))
        self.row_of[(self.batch_of == batch.index) & (self.row_of > row)] -= 1
        for each in self.batches:
            each.members[each.members > index] -= 1

    def locate(self, index: int) -> tuple[Batch, int]:
        """The batch and row of creature `index`."""
        return self.batches[int(self.batch_of[index])], int(self.row_of[index])

    @property
    def commanded(self) -> np.ndarray:
        """Creatures whose commands are written (not frozen, not kinematic: an asleep one
        too, which its commands may wake), whole-roster once a frame rather than batch by
        batch."""
        return np.asarray(~self.frozen & (self.tier != KINEMATIC))

    @property
    def active(self) -> np.ndarray:
        """Creatures stepped this frame (not frozen, not asleep, not kinematic)."""
        return np.asarray(~(self.frozen | self.sleeping) & (self.tier != KINEMATIC))
