"""Unit mesh templates as numpy arrays, scaled per instance in the vertex shader.

Each template has `positions` (n, 3), `normals` (n, 3), `sides` (n,) and triangle
`indices`. A vertex's instance position is `position * scale + side * extend * x`:
capsule caps carry side -1/+1 so one template draws capsules of any length.
Levels of detail: fewer segments for crowds (triangles are the cost without a GPU).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Mesh:
    """A triangle mesh template."""

    positions: np.ndarray
    normals: np.ndarray
    sides: np.ndarray
    indices: np.ndarray

    @property
    def triangles(self) -> int:
        return len(self.indices) // 3

    def vertex_data(self) -> np.ndarray:
        """Interleaved float32 (n, 7): position, normal, side."""
        return np.hstack([self.positions, self.normals, self.sides[:, None]]).astype(np.float32)


def _grid_indices(rows: int, columns: int) -> np.ndarray:
    """Two triangles per cell of a (rows + 1) x (columns + 1) vertex grid, wrapping columns."""
    r, c = np.meshgrid(np.arange(rows), np.arange(columns), indexing="ij")
    a = r * (columns + 1) + c
    b = a + 1
    d = a + columns + 1
    e = d + 1
    # counter-clockwise seen from outside (the front faces OpenGL keeps when culling)
    return np.stack([a, b, d, b, e, d], axis=-1).reshape(-1).astype(np.uint32)


def capsule(segments: int = 10, rings: int = 3) -> Mesh:
    """Unit-radius capsule along +x: two hemispheres (sides -1, +1) joined by a band."""
    # latitude from -x pole to +x pole; the equator row is duplicated (one per side)
    lat_neg = np.linspace(-np.pi / 2, 0.0, rings + 1)
    lat_pos = np.linspace(0.0, np.pi / 2, rings + 1)
    lat = np.concatenate([lat_neg, lat_pos])
    side = np.concatenate([-np.ones(rings + 1), np.ones(rings + 1)])
    lon = np.linspace(0.0, 2 * np.pi, segments + 1)
    la, lo = np.meshgrid(lat, lon, indexing="ij")
    normals = np.stack([np.sin(la), np.cos(la) * np.cos(lo), np.cos(la) * np.sin(lo)], axis=-1)
    sides = np.repeat(side, segments + 1)
    return Mesh(
        positions=normals.reshape(-1, 3),
        normals=normals.reshape(-1, 3),
        sides=sides,
        indices=_grid_indices(len(lat) - 1, segments),
    )


def sphere(segments: int = 10, rings: int = 6) -> Mesh:
    """Unit sphere."""
    lat = np.linspace(-np.pi / 2, np.pi / 2, rings + 1)
    lon = np.linspace(0.0, 2 * np.pi, segments + 1)
    la, lo = np.meshgrid(lat, lon, indexing="ij")
    normals = np.stack([np.cos(la) * np.cos(lo), np.cos(la) * np.sin(lo), np.sin(la)], axis=-1)
    normals = normals.reshape(-1, 3)
    return Mesh(normals, normals, np.zeros(len(normals)), _grid_indices(rings, segments))


def cylinder(segments: int = 16) -> Mesh:
    """Unit cylinder along +z (radius 1, z from -1 to 1) with flat caps."""
    lon = np.linspace(0.0, 2 * np.pi, segments + 1)
    ring = np.stack([np.cos(lon), np.sin(lon), np.zeros_like(lon)], axis=1)
    low, high = ring + [0, 0, -1], ring + [0, 0, 1]
    band_pos = np.vstack([low, high])
    band_normal = np.vstack([ring, ring])
    band_idx = _grid_indices(1, segments)
    cap_pos, cap_normal, cap_idx = [], [], []
    start = len(band_pos)
    for z, normal in ((-1.0, -1.0), (1.0, 1.0)):
        centre = np.array([[0.0, 0.0, z]])
        vertices = np.vstack([centre, ring + [0, 0, z]])
        cap_pos.append(vertices)
        cap_normal.append(np.tile([0.0, 0.0, normal], (len(vertices), 1)))
        k = np.arange(segments)
        tris = np.stack([np.zeros(segments, int), 1 + k, 2 + k], axis=1)
        if normal < 0:
            tris = tris[:, [0, 2, 1]]
        cap_idx.append(tris.reshape(-1) + start)
        start += len(vertices)
    positions = np.vstack([band_pos, *cap_pos])
    return Mesh(
        positions=positions,
        normals=np.vstack([band_normal, *cap_normal]),
        sides=np.zeros(len(positions)),
        indices=np.concatenate([band_idx, *cap_idx]).astype(np.uint32),
    )


# Levels of detail: near, far.
CAPSULE_LODS = (capsule(10, 3), capsule(6, 1))
SPHERE_LOD = sphere(8, 4)
CYLINDER_LOD = cylinder(20)
