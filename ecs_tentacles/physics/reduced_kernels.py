"""The numba kernel of the reduced tier's maps (`physics.reduced`): the full servo
commands pulled into a reduced state, and a reduced state's joints shown on the full
skeleton, each a weighted sum over a group of columns.

Optional, as the other kernels are: `ReducedModel` imports this module only when numba
is installed and falls back to numpy otherwise; both give the same numbers bit for bit
(the same products summed in the same order, the same clip; tests/physics/
test_reduced_kernels.py compares them). The maps run on the stepping threads, once a
share: numpy's passes there hold the interpreter's lock, which the other thread then
waits for between its steps; the kernel releases it.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def group_sums_into(
    values: np.ndarray,
    columns: np.ndarray,
    members: np.ndarray,
    weights: np.ndarray,
    low: np.ndarray,
    high: np.ndarray,
    out: np.ndarray,
    out_columns: np.ndarray,
) -> None:
    """For each row r of `values` and each k: the sum over p, in order, of
    values[r, columns[members[k, p]]] x weights[k, p], clipped into [low[k], high[k]]
    when `low` is not empty (NaN stays NaN), into out[r, out_columns[k]]."""
    clip = low.shape[0] > 0
    for r in range(values.shape[0]):
        for k in range(members.shape[0]):
            total = values[r, columns[members[k, 0]]] * weights[k, 0]
            for p in range(1, members.shape[1]):
                total += values[r, columns[members[k, p]]] * weights[k, p]
            if clip:
                if total < low[k]:
                    total = low[k]
                if total > high[k]:
                    total = high[k]
            out[r, out_columns[k]] = total
