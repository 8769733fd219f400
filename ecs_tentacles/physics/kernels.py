"""The numba kernel of the contact proxies' `sense`: gather every body and every reach
sphere in one pass.

Optional, as the other kernels are: `proxies` imports this module only when numba is
installed and falls back to numpy otherwise; both compute the same numbers bit for bit
(the same operations in the same order; tests/physics/test_contacts.py compares them).
At 10,000 creatures (810,000 bodies) the numpy path took about 55 ms a frame: two
gathers, a subtraction, a norm and a `maximum.reduceat`, each a pass over every body.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def sense(
    store_pos: np.ndarray,
    store_quat: np.ndarray,
    rows: np.ndarray,
    start: np.ndarray,
    count: np.ndarray,
    rbound: np.ndarray,
    out_pos: np.ndarray,
    out_quat: np.ndarray,
    out_centre: np.ndarray,
    out_radius: np.ndarray,
) -> None:
    """Bodies `rows` of the Transform store into `out_pos` / `out_quat` (creature by
    creature: creature c owns `count[c]` bodies from `start[c]`, its mantle first); each
    creature's reach sphere (mantle centre, farthest body surface) into `out_centre` /
    `out_radius`."""
    for c in range(len(start)):
        first = start[c]
        mantle = rows[first]
        cx, cy, cz = store_pos[mantle, 0], store_pos[mantle, 1], store_pos[mantle, 2]
        out_centre[c, 0], out_centre[c, 1], out_centre[c, 2] = cx, cy, cz
        radius = -np.inf
        for i in range(first, first + count[c]):
            row = rows[i]
            x, y, z = store_pos[row, 0], store_pos[row, 1], store_pos[row, 2]
            out_pos[i, 0], out_pos[i, 1], out_pos[i, 2] = x, y, z
            for j in range(4):
                out_quat[i, j] = store_quat[row, j]
            dx, dy, dz = x - cx, y - cy, z - cz
            reach = math.sqrt(dx * dx + dy * dy + dz * dz) + rbound[i]
            if reach > radius:
                radius = reach
        out_radius[c] = radius
