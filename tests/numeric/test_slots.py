"""SlotRows: rows that hold data only while they need it, in a compact pool."""

from __future__ import annotations

import numpy as np
from numpy.testing import assert_array_equal

from ecs_tentacles.numeric.slots import SlotRows


def _items(rows: SlotRows) -> dict[int, list[float]]:
    return {r: rows.pool[s].tolist() for r, s in enumerate(rows.slot.tolist()) if s >= 0}


def test_released_rows_give_their_memory_back_and_the_others_keep_their_data() -> None:
    rows = SlotRows(np.arange(10.0).reshape(5, 2))
    rows.release(np.array([0, 2, 3]))
    assert len(rows.pool) == 2
    assert _items(rows) == {1: [2.0, 3.0], 4: [8.0, 9.0]}
    rows.release(np.array([2]))  # holds nothing already: no change
    assert _items(rows) == {1: [2.0, 3.0], 4: [8.0, 9.0]}


def test_a_row_holds_data_again_and_rows_come_and_go() -> None:
    rows = SlotRows(np.zeros((3, 2)))
    rows.release(np.array([0, 1, 2]))
    slots = rows.hold(np.array([2, 0]), np.array([[5.0, 6.0], [1.0, 2.0]]))
    assert_array_equal(rows.pool[slots], [[5.0, 6.0], [1.0, 2.0]])
    rows.hold(np.array([2]), np.array([7.0, 7.0]))  # held already: overwritten in place
    assert len(rows.pool) == 2 and _items(rows) == {0: [1.0, 2.0], 2: [7.0, 7.0]}
    rows.append(np.array([3.0, 3.0]))
    rows.remove(0)
    assert len(rows) == 3 and _items(rows) == {1: [7.0, 7.0], 2: [3.0, 3.0]}
    copy = rows.copy()
    rows.release(np.array([1]))
    rows.set_to(copy)
    assert _items(rows) == {1: [7.0, 7.0], 2: [3.0, 3.0]}
