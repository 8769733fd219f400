"""The numba kernel of crowd avoidance (`ecs_tentacles.locomotion.avoidance.bend`): one
pass over the near pairs, where the numpy path takes some twenty whole-array operations
of a few microseconds each.

Optional, as the other kernels are (`ecs_tentacles.numeric.optional_kernels`): `bend`
uses it only when numba is installed and falls back to numpy otherwise. Both compute
the same numbers bit for bit: the same operations in the same order, the pairs' forces
summed in pair order as `np.add.at` sums them, no fused multiply-adds (numba contracts
only with `fastmath`). tests/locomotion/test_avoidance.py compares the two.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def bend_pairs(
    pos: np.ndarray,
    radius: np.ndarray,
    heading: np.ndarray,
    steering: np.ndarray,
    to_goal: np.ndarray,
    a: np.ndarray,
    b: np.ndarray,
    reach: float,
    strength: float,
    behind: float,
    sidestep: float,
    out: np.ndarray,
) -> None:
    """`out` (n, 2, zeros): each creature's avoidance term from the near pairs (a[k],
    b[k]) whose a steers, faded near its goal, times `strength` (`bend`'s numbers)."""
    ahead_share = (1.0 - behind) * 0.5
    for k in range(len(a)):
        i, j = a[k], b[k]
        if not steering[i]:
            continue
        dx, dy = pos[j, 0] - pos[i, 0], pos[j, 1] - pos[i, 1]
        distance = math.hypot(dx, dy)
        scale = max(distance, 1e-9)
        tx, ty = dx / scale, dy / scale
        gap = distance - radius[i] - radius[j]
        push = min(max(1.0 - gap / reach, 0.0), 2.0)
        push = push * push
        ahead = tx * heading[i, 0] + ty * heading[i, 1]
        weight = push * (behind + ahead_share * (1.0 + ahead))
        side = sidestep * max(ahead, 0.0)
        out[i, 0] += (side * ty - tx) * weight
        out[i, 1] += (side * -tx - ty) * weight
    for i in range(len(out)):
        fade = min(max(to_goal[i] / max(radius[i], 1e-9), 0.0), 1.0)
        factor = strength * fade
        out[i, 0] *= factor
        out[i, 1] *= factor
