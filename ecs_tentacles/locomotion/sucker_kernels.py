"""The numba kernel of the suckers system's release test (`locomotion/systems/suckers.py`).

Optional, as the other kernels are (`ecs_tentacles.numeric.optional_kernels`): the
system uses it only when numba is installed and falls back to numpy otherwise. Both
find the same reasons from the same numbers: each held sucker's point is rotated as
`quaternion_kernels.rotate` does (`quat_rotate`'s kernel), its distances summed in
`np.linalg.norm`'s order. tests/locomotion/systems/test_suckers.py compares the two.
The numpy path takes about a dozen whole-array passes over the held suckers a frame.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

REPLAYED, COMMAND, STRETCH, REACH = 1, 2, 3, 4  # `release_reasons` codes, in test order


@njit(cache=True, nogil=True)
def release_reasons(
    held: np.ndarray,
    tentacle_row: np.ndarray,
    creature_row: np.ndarray,
    action: np.ndarray,
    gripping: np.ndarray,
    tip: np.ndarray,
    replayed: np.ndarray,
    link_row: np.ndarray,
    offset: np.ndarray,
    pos: np.ndarray,
    quat: np.ndarray,
    anchor: np.ndarray,
    base_row: np.ndarray,
    release_stretch: np.ndarray,
    release_reach: np.ndarray,
    length: np.ndarray,
) -> np.ndarray:
    """Per held sucker row, the first reason it lets go (0: none): its creature is
    replayed (`replayed` per creature row), its tentacle's action grips no more (or it
    is not the tip), it is stretched farther than `release_stretch` from its anchor, or
    the tentacle's base is farther than `release_reach` tentacle lengths from it."""
    out = np.zeros(len(held), dtype=np.int8)
    for i in range(len(held)):
        row = held[i]
        k = tentacle_row[row]
        c = creature_row[k]
        if replayed[c]:
            out[i] = REPLAYED
            continue
        if not (gripping[action[k]] and tip[k] == row):
            out[i] = COMMAND
            continue
        link = link_row[row]
        w, x, y, z = quat[link, 0], quat[link, 1], quat[link, 2], quat[link, 3]
        v0, v1, v2 = offset[row, 0], offset[row, 1], offset[row, 2]
        t0 = 2.0 * (y * v2 - z * v1)
        t1 = 2.0 * (z * v0 - x * v2)
        t2 = 2.0 * (x * v1 - y * v0)
        p0 = pos[link, 0] + (v0 + w * t0 + (y * t2 - z * t1))
        p1 = pos[link, 1] + (v1 + w * t1 + (z * t0 - x * t2))
        p2 = pos[link, 2] + (v2 + w * t2 + (x * t1 - y * t0))
        d0, d1, d2 = p0 - anchor[row, 0], p1 - anchor[row, 1], p2 - anchor[row, 2]
        if math.sqrt(d0 * d0 + d1 * d1 + d2 * d2) > release_stretch[c]:
            out[i] = STRETCH
            continue
        base = base_row[k]
        b0, b1 = pos[base, 0] - anchor[row, 0], pos[base, 1] - anchor[row, 1]
        if math.sqrt(b0 * b0 + b1 * b1) > release_reach[c] * length[k]:
            out[i] = REACH
    return out
