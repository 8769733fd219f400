"""The numba kernels of the terrain's queries against its spheres: the topmost surface
above points (`TerrainGround.surface`), the distance from points (`distance`) and
which balls reach one (`touches_obstacle`), every point against every sphere in one
pass; and which points lie within each solid's bounding sphere or circle
(`under_bounds`, the test every query starts with). `TerrainGround` hands them its
spheres and asks numpy, solid by solid, about the rest; the answers are the largest
top, the smallest distance and an or, which do not depend on the order the solids are
taken in.

Optional, as the other kernels are: numpy computes the same numbers bit for bit (the
same operations in the same order: a bounding-sphere test on squares summed
(x^2 + y^2) + z^2, then the sphere's own test; tests/terrain/test_solid_kernels.py
compares them). 64 creatures on the rocky preset asked these three about 0.6 ms a
frame through numpy's solid-by-solid loop; the sandbox's blob shadows asked `surface`
about 5,600 points among 171 rocks each frame at 256 creatures, 23 ms of CPU for
numpy's bounding test (a (points, solids, 2) array of gaps) against about 1 ms here.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True, nogil=True, inline="always")
def _largest(a: float, b: float) -> float:
    """`np.maximum(a, b)`: a NaN wins, a tie gives `a`."""
    if a >= b or a != a:
        return a
    return b


@njit(cache=True, nogil=True, inline="always")
def _smallest(a: float, b: float) -> float:
    """`np.minimum(a, b)`: a NaN wins, a tie gives `a`."""
    if a <= b or a != a:
        return a
    return b


@njit(cache=True, nogil=True)
def sphere_tops(xy: np.ndarray, centres: np.ndarray, radii: np.ndarray, out: np.ndarray) -> None:
    """`out` (n,) raised to each sphere's top above points `xy` (n, 2) it lies under:
    centre height plus sqrt(r^2 - d^2), d the point's distance from the centre in x, y."""
    for p in range(xy.shape[0]):
        best = out[p]
        for k in range(centres.shape[0]):
            gx, gy = xy[p, 0] - centres[k, 0], xy[p, 1] - centres[k, 1]
            d2 = gx * gx + gy * gy
            r2 = radii[k] * radii[k]
            if d2 <= r2:
                best = _largest(best, centres[k, 2] + math.sqrt(max(r2 - d2, 0.0)))
        out[p] = best


@njit(cache=True, nogil=True)
def sphere_distances(
    points: np.ndarray, centres: np.ndarray, radii: np.ndarray, pad: float, out: np.ndarray
) -> None:
    """`out` (n,) lowered to each sphere's signed distance from points `points` (n, 3)
    within `pad` of it (farther ones are left as they are)."""
    for p in range(points.shape[0]):
        best = out[p]
        for k in range(centres.shape[0]):
            gx = points[p, 0] - centres[k, 0]
            gy = points[p, 1] - centres[k, 1]
            gz = points[p, 2] - centres[k, 2]
            d2 = (gx * gx + gy * gy) + gz * gz
            bound = radii[k] + pad
            if d2 <= bound * bound:
                best = _smallest(best, math.sqrt(d2) - radii[k])
        out[p] = best


@njit(cache=True, nogil=True)
def sphere_touches(
    points: np.ndarray, reach: np.ndarray, centres: np.ndarray, radii: np.ndarray, out: np.ndarray
) -> None:
    """`out` (n,) set where the ball at `points` (n, 3) of radius `reach` (n,) meets a
    sphere (its signed distance from the point at most `reach`)."""
    for p in range(points.shape[0]):
        if out[p]:
            continue
        for k in range(centres.shape[0]):
            gx = points[p, 0] - centres[k, 0]
            gy = points[p, 1] - centres[k, 1]
            gz = points[p, 2] - centres[k, 2]
            d2 = (gx * gx + gy * gy) + gz * gz
            bound = radii[k] + reach[p]
            if d2 <= bound * bound and math.sqrt(d2) - radii[k] <= reach[p]:
                out[p] = True
                break


@njit(cache=True, nogil=True)
def under_bounds(
    points: np.ndarray, middles: np.ndarray, reaches: np.ndarray, pads: np.ndarray
) -> np.ndarray:
    """(n, k) bool: point p (of `points`, (n, 2) or (n, 3)) lies within bound k (centre
    `middles[k]`, radius `reaches[k]` grown by `pads[p]`): squares summed
    (x^2 + y^2) + z^2 against the grown radius squared, as numpy's test sums them."""
    n, k, dims = points.shape[0], middles.shape[0], points.shape[1]
    inside = np.zeros((n, k), np.bool_)
    for p in range(n):
        for s in range(k):
            gx = points[p, 0] - middles[s, 0]
            gy = points[p, 1] - middles[s, 1]
            squares = gx * gx + gy * gy
            if dims == 3:
                gz = points[p, 2] - middles[s, 2]
                squares += gz * gz
            reach = reaches[s] + pads[p]
            inside[p, s] = squares <= reach * reach
    return inside


@njit(cache=True, nogil=True, inline="always")
def _piece_distance(points: np.ndarray, p: int, normals: np.ndarray, offsets: np.ndarray,
                    k: int) -> float:  # fmt: skip
    """Point `p`'s signed distance from convex piece `k`: its largest plane distance,
    each a dot product summed x, y, z in that order (as `ConvexPieces` sums it)."""
    largest = -math.inf
    for f in range(normals.shape[1]):
        plane = (
            points[p, 0] * normals[k, f, 0]
            + points[p, 1] * normals[k, f, 1]
            + points[p, 2] * normals[k, f, 2]
        ) - offsets[k, f]
        largest = _largest(largest, plane) if f else plane
    return largest


@njit(cache=True, nogil=True, inline="always")
def _within(points: np.ndarray, p: int, centres: np.ndarray, k: int, reach: float) -> bool:
    """Whether point `p` lies within `reach` of piece `k`'s centre: squares summed
    (x^2 + y^2) + z^2 against `reach` squared."""
    gx = points[p, 0] - centres[k, 0]
    gy = points[p, 1] - centres[k, 1]
    gz = points[p, 2] - centres[k, 2]
    inside: bool = (gx * gx + gy * gy) + gz * gz <= reach * reach
    return inside


@njit(cache=True, nogil=True)
def piece_distances(points: np.ndarray, pad: float, centres: np.ndarray, bounds: np.ndarray,
                    normals: np.ndarray, offsets: np.ndarray, out: np.ndarray) -> None:  # fmt: skip
    """`out` (n,) lowered to each convex piece's signed distance from points (n, 3)
    within `pad` of its bounding sphere (`ConvexPieces.lower_distances`)."""
    for p in range(points.shape[0]):
        best = out[p]
        for k in range(centres.shape[0]):
            if _within(points, p, centres, k, bounds[k] + pad):
                best = _smallest(best, _piece_distance(points, p, normals, offsets, k))
        out[p] = best


@njit(cache=True, nogil=True)
def piece_touches(points: np.ndarray, reach: np.ndarray, centres: np.ndarray,
                  bounds: np.ndarray, normals: np.ndarray, offsets: np.ndarray,
                  out: np.ndarray) -> None:  # fmt: skip
    """`out` (n,) set where the ball at `points` (n, 3) of radius `reach` (n,) meets a
    convex piece (`ConvexPieces.touch`)."""
    for p in range(points.shape[0]):
        if out[p]:
            continue
        for k in range(centres.shape[0]):
            if _within(points, p, centres, k, bounds[k] + reach[p]):
                if _piece_distance(points, p, normals, offsets, k) <= reach[p]:
                    out[p] = True
                    break
