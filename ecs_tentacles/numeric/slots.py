"""Rows of a table that hold data only while they need it: a compact pool and a map.

    saved = SlotRows(np.repeat(states[:, None], 2, axis=1))  # every row holds one
    saved.release(np.flatnonzero(replayed))  # their data dropped, the pool compacted
    saved.hold(np.array([7]), states[[7], None])  # row 7 holds data again
    saved.pool[saved.slot[7]]  # its data

`slot` (rows,) gives each row's place in `pool` (held, *item), or -1 where the row holds
nothing. For per-creature data that only some creatures use (the physics health check's
saved states: only creatures stepped by MuJoCo are ever restored), so a crowd of
10,000 mostly replayed creatures keeps a pool of the few hundred it steps.
"""

from __future__ import annotations

import numpy as np


class SlotRows:
    """Per-row items (each of `pool`'s item shape) held by some rows only."""

    def __init__(self, items: np.ndarray):
        """Every row holds its item of `items` (rows, *item), in row order."""
        self.pool = items
        self.slot = np.arange(len(items), dtype=np.int64)

    @classmethod
    def empty(cls, rows: int, item: tuple[int, ...]) -> SlotRows:
        """`rows` rows holding nothing (items of shape `item`, float64)."""
        out = cls.__new__(cls)
        out.pool, out.slot = np.zeros((0, *item)), np.full(rows, -1, dtype=np.int64)
        return out

    def __len__(self) -> int:
        return len(self.slot)

    def copy(self) -> SlotRows:
        """An independent copy (pool and map)."""
        out = SlotRows.__new__(SlotRows)
        out.pool, out.slot = self.pool.copy(), self.slot.copy()
        return out

    def set_to(self, other: SlotRows) -> None:
        """Hold what `other` holds (copied: `other` can be set again later)."""
        self.pool, self.slot = other.pool.copy(), other.slot.copy()

    def hold(self, rows: np.ndarray, items: np.ndarray) -> np.ndarray:
        """Rows `rows` (distinct) hold `items` (len(rows), *item) from now on, in slots
        taken for the rows that held none; returns their slots."""
        rows = np.asarray(rows, dtype=np.int64)
        new = rows[self.slot[rows] < 0]
        if len(new):
            self.slot[new] = len(self.pool) + np.arange(len(new))
            grown = np.empty((len(self.pool) + len(new), *self.pool.shape[1:]), self.pool.dtype)
            grown[: len(self.pool)] = self.pool
            self.pool = grown
        slots: np.ndarray = self.slot[rows]
        self.pool[slots] = items
        return slots

    def release(self, rows: np.ndarray) -> None:
        """Rows `rows` hold nothing from now on; the pool keeps the others, in order."""
        rows = np.asarray(rows, dtype=np.int64)
        gone = self.slot[rows]
        gone = gone[gone >= 0]
        if not len(gone):
            return
        kept = np.ones(len(self.pool), dtype=bool)
        kept[gone] = False
        moved = np.cumsum(kept) - 1  # old slot -> new slot (for the kept ones)
        self.slot[rows] = -1
        held = self.slot >= 0
        self.slot[held] = moved[self.slot[held]]
        self.pool = self.pool[kept]

    def append(self, item: np.ndarray) -> None:
        """One more row at the end, holding `item`."""
        self.slot = np.append(self.slot, len(self.pool))
        self.pool = np.concatenate([self.pool, item[None]])

    def remove(self, row: int) -> None:
        """Take row `row` out (its item with it); the rows after it move up one."""
        self.release(np.array([row]))
        self.slot = np.delete(self.slot, row)
