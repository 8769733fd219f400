"""Boulders: a scene's `{"shape": "rock", "size": [x, y, z], "seed": s}` -> its vertices.

    vertices = rock_vertices((0.8, 0.6, 0.45), seed=7)   # (k, 3), metres, one convex piece

A sphere of `POINTS` evenly spread points, each pushed out or in along its direction
by OpenSimplex noise on the sphere (`OCTAVES`, strength `ROUGHNESS`: the same for the
same seed), stretched to `size` (the box it fills, exactly) and closed by its convex
hull: a chipped, faceted stone. It is one convex piece, so what MuJoCo collides with,
what the sandbox draws (flat-shaded hull faces) and what the exporters write are the
same mesh. The origin is the middle of its box.
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import lru_cache

import numpy as np

POINTS = 160  # on the sphere (their hull keeps about 60: MuJoCo collides with it quickly)
OCTAVES = 3  # noise layers, each twice as fine and half as strong
ROUGHNESS = 0.45  # the largest push in or out, as a share of the radius
FREQUENCY = 1.3  # bumps of the coarsest layer across the unit sphere


@lru_cache(maxsize=1)
def _directions() -> np.ndarray:
    """`POINTS` unit vectors spread evenly over the sphere (a golden-angle spiral)."""
    k = np.arange(POINTS) + 0.5
    z = 1.0 - 2.0 * k / POINTS
    angle = np.pi * (3.0 - np.sqrt(5.0)) * k
    ring = np.sqrt(1.0 - z * z)
    return np.column_stack([ring * np.cos(angle), ring * np.sin(angle), z])


def rock_vertices(size: Sequence[float], seed: int) -> np.ndarray:
    """The vertices (k, 3) of the convex hull of a noise-displaced sphere filling the box
    `size` (full extents x, y, z, metres) about the origin; the same for the same seed."""
    import opensimplex
    from scipy.spatial import ConvexHull

    directions = _directions()
    generator = opensimplex.OpenSimplex(int(seed))
    push = np.zeros(len(directions))
    weight = 1.0
    for octave in range(OCTAVES):
        frequency = FREQUENCY * 2.0**octave
        offset = 31.7 * (octave + 1)  # each layer from another part of the noise
        at = (directions * frequency + offset).tolist()
        push += weight * np.array([generator.noise3(x, y, z) for x, y, z in at])
        weight *= 0.5
    push /= max(float(np.abs(push).max()), 1e-9)
    points = directions * (1.0 + ROUGHNESS * push)[:, None]
    low, high = points.min(axis=0), points.max(axis=0)
    points = (points - 0.5 * (low + high)) / (high - low) * np.asarray(size, dtype=np.float64)
    hull = ConvexHull(points)
    return np.ascontiguousarray(points[np.sort(hull.vertices)])
