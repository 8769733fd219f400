"""The numba kernel of tentacle selection on the plane (`systems/locomotion/
tentacle_selection.py`): each live tentacle's vectors mantle -> goal (turned by the
avoidance term) and mantle -> base, and the thesis's push/pull test on them, in one
pass where the numpy path takes some twenty whole-array operations.

Optional, as the other kernels are (`ecs_tentacles.numeric.optional_kernels`): the
system uses it only when numba is installed and falls back to numpy otherwise. Both
compute the same numbers bit for bit: the same operations in the same order, no fused
multiply-adds (numba contracts only with `fastmath`).
tests/systems/locomotion/test_tentacle_selection.py compares the two.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def flat_vectors(
    pos: np.ndarray,
    mantle_row: np.ndarray,
    steer: np.ndarray,
    avoidance: np.ndarray,
    base_row: np.ndarray,
    creature_row: np.ndarray,
    live: np.ndarray,
    tolerance: float,
    to_goal: np.ndarray,
    to_base: np.ndarray,
    pull: np.ndarray,
    cos: np.ndarray,
) -> None:
    """At tentacle rows `live`: `to_goal` (the steer point from the mantle, turned by
    the avoidance term as `avoidance.bent` turns it), `to_base` (the tentacle's base
    from the mantle), `cos` of their angle and `pull` (cos >= -tolerance)."""
    for k in range(len(live)):
        row = live[k]
        creature = creature_row[row]
        mantle = mantle_row[creature]
        mx, my = pos[mantle, 0], pos[mantle, 1]
        gx, gy = steer[creature, 0] - mx, steer[creature, 1] - my
        tx, ty = avoidance[creature, 0], avoidance[creature, 1]
        if tx != 0.0 or ty != 0.0:
            length = math.hypot(gx, gy)
            gx, gy = gx + length * tx, gy + length * ty
        base = base_row[row]
        bx, by = pos[base, 0] - mx, pos[base, 1] - my
        to_goal[row, 0], to_goal[row, 1] = gx, gy
        to_base[row, 0], to_base[row, 1] = bx, by
        dot = gx * bx + gy * by
        lengths = math.hypot(gx, gy) * math.hypot(bx, by)
        c = dot / max(lengths, 1e-12)
        cos[row] = c
        pull[row] = c >= -tolerance
