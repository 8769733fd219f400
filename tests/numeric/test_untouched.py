"""Zeroed tables resident only where written (`ecs_tentacles.numeric.untouched`)."""

from __future__ import annotations

import os
import pickle

import numpy as np
import pytest

from ecs_tentacles.numeric.untouched import is_untouched, untouched_zeros
from ecs_tentacles.physics.heap import resident_bytes

PAGE = os.sysconf("SC_PAGE_SIZE")
linux = pytest.mark.skipif(resident_bytes(np.zeros(1)) is None, reason="mincore: Linux only")


@linux
def test_a_table_is_zeros_and_resident_only_where_written() -> None:
    table = untouched_zeros((10_000, 160))  # 12.8 MB, a crowd's servo gains
    assert table.shape == (10_000, 160) and table.dtype == np.float64
    assert table.flags.c_contiguous and table.flags.writeable
    assert resident_bytes(table) == 0
    table[::100] = 1.0  # 100 rows of 1,280 bytes
    resident = resident_bytes(table)
    assert resident is not None and 0 < resident <= 100 * 2 * PAGE
    assert table.sum() == 100 * 160  # (reading the rest reads zeros)


def test_copies_and_pickles_are_ordinary_arrays_with_the_same_numbers() -> None:
    table = untouched_zeros((50, 3), np.int64)
    table[7] = [1, 2, 3]
    for other in (table.copy(), pickle.loads(pickle.dumps(table))):
        np.testing.assert_array_equal(other, table)
        other[0] = 9  # its own memory
    assert not table[0].any()
    assert untouched_zeros((0, 4)).shape == (0, 4)


def test_a_table_and_its_views_are_known_as_untouched_its_copies_not() -> None:
    table = untouched_zeros((20, 3))
    assert is_untouched(table) and is_untouched(table[4:9]) and is_untouched(table.reshape(-1))
    assert not is_untouched(table.copy()) and not is_untouched(np.zeros((20, 3)))
