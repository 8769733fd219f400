"""run_slice: a run of consecutive rows is read as a slice, anything else is not;
ordinals: items numbered within their keys, as a count per key would number them."""

from __future__ import annotations

import numpy as np

from ecs_tentacles.numeric.rows import ordinals, run_slice


def test_a_run_of_rows_is_a_slice_that_reads_the_same_rows() -> None:
    rows = np.arange(5, 12)
    span = run_slice(rows)
    assert span == slice(5, 12)
    data = np.arange(20.0)
    assert np.array_equal(data[span], data[rows])


def test_gaps_reversed_repeated_or_no_rows_are_not_a_slice() -> None:
    for rows in ([1, 2, 4], [3, 2, 1], [2, 2, 3], []):
        assert run_slice(np.asarray(rows, dtype=np.int64)) is None


def test_ordinals_number_items_within_their_key_in_order() -> None:
    assert ordinals(np.array([7, 3, 7, 7, 3, -1])).tolist() == [0, 0, 1, 2, 1, 0]
    assert ordinals(np.zeros(0, dtype=np.int64)).tolist() == []
    rng = np.random.default_rng(5)
    keys = rng.integers(-3, 4, 500)
    counted, seen = [], dict[int, int]()
    for key in keys.tolist():
        counted.append(seen.get(key, 0))
        seen[key] = counted[-1] + 1
    assert ordinals(keys).tolist() == counted
