"""The numba kernel of the goals system (`locomotion/systems/goals.py`): the creatures
whose mantle is within their goal's radius, on the ground plane, in one pass where the
numpy path takes eight whole-array operations a frame.

Optional, as the other kernels are (`ecs_tentacles.numeric.optional_kernels`): the
system uses it only when numba is installed and falls back to numpy otherwise. Both
compare the same numbers: dx * dx + dy * dy (two terms: the same sum in any order)
against radius * radius. tests/locomotion/systems/test_goals.py compares the two.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def reached(
    pos: np.ndarray,
    mantle_row: np.ndarray,
    goal: np.ndarray,
    goal_radius: np.ndarray,
    has_goal: np.ndarray,
) -> np.ndarray:
    """Creature rows with a goal whose mantle (`pos[mantle_row]`) is within `goal_radius`
    of it in x and y."""
    out = np.empty(len(has_goal), dtype=np.int64)
    found = 0
    for c in range(len(has_goal)):
        if not has_goal[c]:
            continue
        m = mantle_row[c]
        dx, dy = pos[m, 0] - goal[c, 0], pos[m, 1] - goal[c, 1]
        if dx * dx + dy * dy <= goal_radius[c] * goal_radius[c]:
            out[found] = c
            found += 1
    return out[:found]
