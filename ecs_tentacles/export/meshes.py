"""Lean triangle meshes of capsules and cylinders, for exporters.

Both are lathes: a profile (distance along the axis, distance from it, and the
normal in that plane) turned about the local +x axis. A profile point on the axis
becomes one pole vertex with a triangle fan; consecutive profile points at the same
place (a sharp rim with two normals) get no triangles between them, so there are no
degenerate triangles. Triangles wind counter-clockwise seen from outside.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Mesh:
    """`positions` and `normals` (n, 3) float32, `indices` (m * 3,) uint16 triangles."""

    positions: np.ndarray
    normals: np.ndarray
    indices: np.ndarray


# (x, r, nx, nr) rows: along the axis, from the axis, the normal's two components
Profile = list[tuple[float, float, float, float]]


def lathe(profile: Profile, segments: int = 12) -> Mesh:
    """Turn `profile` about +x in `segments` steps."""
    theta = 2.0 * np.pi * np.arange(segments) / segments
    cos, sin = np.cos(theta), np.sin(theta)
    positions: list[np.ndarray] = []
    normals: list[np.ndarray] = []
    rings: list[list[int]] = []  # vertex ids of each profile point (1 for a pole)
    for x, r, nx, nr in profile:
        start = sum(len(p) for p in positions)
        if r == 0.0:
            positions.append(np.array([[x, 0.0, 0.0]]))
            normals.append(np.array([[np.sign(nx), 0.0, 0.0]]))
            rings.append([start])
        else:
            positions.append(np.stack([np.full(segments, x), r * cos, r * sin], axis=1))
            normals.append(np.stack([np.full(segments, nx), nr * cos, nr * sin], axis=1))
            rings.append(list(range(start, start + segments)))
    triangles: list[tuple[int, int, int]] = []
    for k in range(len(profile) - 1):
        (x0, r0, *_), (x1, r1, *_) = profile[k], profile[k + 1]
        if x0 == x1 and r0 == r1:
            continue  # a rim: same place, another normal
        a_ring, b_ring = rings[k], rings[k + 1]
        for j in range(segments):
            nxt = (j + 1) % segments
            if len(a_ring) == 1:  # fan from the first pole
                triangles.append((a_ring[0], b_ring[nxt], b_ring[j]))
            elif len(b_ring) == 1:  # fan into the last pole
                triangles.append((a_ring[j], a_ring[nxt], b_ring[0]))
            else:
                a, d, b, c = a_ring[j], a_ring[nxt], b_ring[j], b_ring[nxt]
                triangles.extend([(a, d, b), (d, c, b)])
    normal = np.concatenate(normals)
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    return Mesh(
        positions=np.concatenate(positions).astype(np.float32),
        normals=normal.astype(np.float32),
        indices=np.asarray(triangles, dtype=np.uint16).reshape(-1),
    )


def capsule(length: float, radius: float, segments: int = 12, cap_rings: int = 3) -> Mesh:
    """A capsule along +x: spine `length` between the cap centres, `radius`."""
    half = 0.5 * length
    profile: Profile = []
    for phi in np.linspace(-0.5 * np.pi, 0.0, cap_rings + 1):
        s, c = float(np.sin(phi)), float(np.cos(phi))
        profile.append((-half + radius * s, radius * c if phi != -0.5 * np.pi else 0.0, s, c))
    for phi in np.linspace(0.0, 0.5 * np.pi, cap_rings + 1):
        s, c = float(np.sin(phi)), float(np.cos(phi))
        profile.append((half + radius * s, radius * c if phi != 0.5 * np.pi else 0.0, s, c))
    return lathe(profile, segments)


def cylinder_x(height: float, radius: float, segments: int = 16) -> Mesh:
    """A closed cylinder along +x, centred on the origin."""
    h = 0.5 * height
    profile: Profile = [
        (-h, 0.0, -1.0, 0.0),
        (-h, radius, -1.0, 0.0),
        (-h, radius, 0.0, 1.0),
        (h, radius, 0.0, 1.0),
        (h, radius, 1.0, 0.0),
        (h, 0.0, 1.0, 0.0),
    ]
    return lathe(profile, segments)


def rotated(mesh: Mesh, matrix: np.ndarray) -> Mesh:
    """`mesh` with positions and normals multiplied by a rotation `matrix` (3, 3)."""
    m = np.asarray(matrix, dtype=np.float64)
    return Mesh(
        positions=(mesh.positions.astype(np.float64) @ m.T).astype(np.float32),
        normals=(mesh.normals.astype(np.float64) @ m.T).astype(np.float32),
        indices=mesh.indices,
    )


# Local axis X -> axis Z, keeping handedness (a cyclic permutation of the axes).
X_TO_Z = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]])


def body_mesh(shape: str, axis: str, radius: float, length: float) -> Mesh:
    """The mesh of a take body: a capsule or cylinder along its local `axis` (X or Z)."""
    mesh = capsule(length, radius) if shape == "capsule" else cylinder_x(length, radius)
    if axis == "X":
        return mesh
    if axis == "Z":
        return rotated(mesh, X_TO_Z)
    raise ValueError(f"body axis must be X or Z, got {axis!r}")
