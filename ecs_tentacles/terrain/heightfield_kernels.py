"""The numba kernels of the heightfield's queries (`terrain.heightfield.Heightfield`): its
heights under points (`field_heights`) and its slope's normals (`field_normals`), each
cell two triangles as MuJoCo's are.

Optional, as the other kernels are: `Heightfield` imports this module only when numba is
installed (`ECS_TENTACLES_SENSE=numpy` turns it off, with the contact proxies' kernels)
and falls back to numpy otherwise; both compute the same numbers bit for bit.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True, nogil=True, inline="always")
def _field_height(
    h: np.ndarray, width: float, depth: float, lowest: float, x: float, y: float
) -> float:
    """`field_heights` at one point (x, y)."""
    rows, cols = h.shape
    if abs(x) > 0.5 * width or abs(y) > 0.5 * depth:
        return lowest
    u = min(max((x / width + 0.5) * (cols - 1), 0.0), cols - 1.0)
    v = min(max((y / depth + 0.5) * (rows - 1), 0.0), rows - 1.0)
    i = min(int(v), rows - 2)
    j = min(int(u), cols - 2)
    fu, fv = u - j, v - i
    h00, h01, h10, h11 = h[i, j], h[i, j + 1], h[i + 1, j], h[i + 1, j + 1]
    if fu >= fv:  # below the diagonal: (i, j), (i, j + 1), (i + 1, j + 1)
        return float(h00 + fu * (h01 - h00) + fv * (h11 - h01))
    return float(h00 + fv * (h10 - h00) + fu * (h11 - h10))


@njit(cache=True, nogil=True)
def field_heights(
    h: np.ndarray, width: float, depth: float, lowest: float, xy: np.ndarray, out: np.ndarray
) -> None:
    """`ground.Heightfield.height` for every point of `xy` into `out`: each cell is two triangles
    split along (i, j) - (i + 1, j + 1), as MuJoCo's are; `lowest` outside the field."""
    for k in range(xy.shape[0]):
        out[k] = _field_height(h, width, depth, lowest, xy[k, 0], xy[k, 1])


@njit(cache=True, nogil=True)
def field_normals(
    h: np.ndarray,
    width: float,
    depth: float,
    lowest: float,
    cell: np.ndarray,
    xy: np.ndarray,
    out: np.ndarray,
) -> None:
    """`ground.Heightfield.slope_normal` for every point of `xy` into `out` (n, 3): the
    heights half a cell (`cell`: dx, dy) either side, their gradient, normalised with
    the squares summed as numpy's norm sums the rows of an (n, 3) array: column by
    column, (x^2 + y^2) + z^2."""
    dx, dy = cell[0], cell[1]
    ex, ey = 0.5 * dx, 0.5 * dy
    for k in range(xy.shape[0]):
        x, y = xy[k, 0], xy[k, 1]
        east = _field_height(h, width, depth, lowest, x + ex, y + 0.0)
        west = _field_height(h, width, depth, lowest, x - ex, y - 0.0)
        north = _field_height(h, width, depth, lowest, x + 0.0, y + ey)
        south = _field_height(h, width, depth, lowest, x - 0.0, y - ey)
        nx, ny = -((east - west) / dx), -((north - south) / dy)
        length = math.sqrt((nx * nx + ny * ny) + 1.0)
        out[k, 0], out[k, 1], out[k, 2] = nx / length, ny / length, 1.0 / length
