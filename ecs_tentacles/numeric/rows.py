"""Row-index helpers: a run of consecutive rows read as a slice (a copy, not a gather),
a row taken out of an array in place, and items numbered within their groups."""

from __future__ import annotations

import numpy as np


def run_slice(rows: np.ndarray) -> slice | None:
    """`rows` (1-D) as one slice when they are consecutive and ascending, else None."""
    if not len(rows) or not bool(np.all(np.diff(rows) == 1)):
        return None
    return slice(int(rows[0]), int(rows[-1]) + 1)


def without_row(array: np.ndarray, row: int) -> np.ndarray:
    """`array` without row `row`: the rows after it moved up in place (no new buffer,
    unlike `np.delete`; a despawn in a big crowd moves megabytes of state)."""
    array[row:-1] = array[row + 1 :]
    return array[:-1]


def ordinals(keys: np.ndarray) -> np.ndarray:
    """Each item's place among the items of its key, in order: [7, 3, 7, 7, 3] ->
    [0, 0, 1, 2, 1] (the k-th sucker of a body, the k-th curve of a creature)."""
    keys = np.asarray(keys).reshape(-1)
    by_key = np.argsort(keys, kind="stable")
    starts = np.flatnonzero(np.diff(keys[by_key], prepend=keys[by_key][:1] - 1))
    places = np.empty(len(keys), dtype=np.int64)
    places[by_key] = np.arange(len(keys)) - np.repeat(starts, np.diff(starts, append=len(keys)))
    return places
