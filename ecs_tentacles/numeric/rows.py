"""Row-index helpers: a run of consecutive rows read as a slice (a copy, not a gather),
and a row taken out of an array in place."""

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
