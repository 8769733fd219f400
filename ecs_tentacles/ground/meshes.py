"""Triangle meshes of the ground (`ecs_tentacles.ground.Ground`), for drawing and export.

    terrain, solids = ground_meshes(ground)   # StaticMesh or None, StaticMesh or None

`terrain` is the heightfield's surface, triangulated exactly as MuJoCo collides with it
(each cell split along its (i, j) - (i + 1, j + 1) diagonal), with smooth normals;
`solids` is every obstacle in one mesh (boxes, cylinders, spheres, the convex pieces of
mesh obstacles), flat-shaded. World coordinates, metres, counter-clockwise from outside.
The plane has neither (the renderer draws its grid; exporters write no ground).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ecs_tentacles.ground import Ground, Solid

# how the sandbox and the exporters colour them (rgb 0..1): sand and earth, grey rock
COLOURS = {"terrain": (0.62, 0.56, 0.44), "obstacles": (0.50, 0.50, 0.52)}
CYLINDER_SEGMENTS = 24
SPHERE_SEGMENTS, SPHERE_RINGS = 24, 12


@dataclass(frozen=True)
class StaticMesh:
    """Vertices (n, 3), unit normals (n, 3) and triangles (m, 3) of vertex indices."""

    vertices: np.ndarray
    normals: np.ndarray
    triangles: np.ndarray


def ground_meshes(ground: Ground) -> tuple[StaticMesh | None, StaticMesh | None]:
    """(heightfield, solids) meshes of `ground`; None where it has none."""
    field = heightfield_mesh(ground) if ground.heightfield is not None else None
    solids = [solid_mesh(s) for s in ground.solids]
    return field, (merge(solids) if solids else None)


def heightfield_mesh(ground: Ground) -> StaticMesh:
    field = ground.heightfield
    assert field is not None
    rows, cols = field.heights.shape
    x = np.linspace(-0.5 * field.size[0], 0.5 * field.size[0], cols)
    y = np.linspace(-0.5 * field.size[1], 0.5 * field.size[1], rows)
    gx, gy = np.meshgrid(x, y)  # (rows, cols): row i at y[i], column j at x[j]
    vertices = np.stack([gx, gy, field.heights], axis=-1).reshape(-1, 3)
    normals = field.slope_normal(vertices[:, :2])
    i, j = np.meshgrid(np.arange(rows - 1), np.arange(cols - 1), indexing="ij")
    a = (i * cols + j).ravel()
    b, c, d = a + 1, a + cols, a + cols + 1  # (i, j+1), (i+1, j), (i+1, j+1)
    triangles = np.concatenate([np.stack([a, b, d], 1), np.stack([a, d, c], 1)])
    return StaticMesh(vertices, normals, triangles.astype(np.int64))


def solid_mesh(solid: Solid) -> StaticMesh:
    """One obstacle as a flat-shaded mesh in world coordinates."""
    if solid.kind == "box":
        local = _box(np.asarray(solid.size))
    elif solid.kind == "cylinder":
        local = _cylinder(*solid.size)
    elif solid.kind == "sphere":
        local = _sphere(solid.size[0])
    else:
        local = merge([_hull(piece) for piece in solid.pieces])
    vertices = local.vertices @ solid.rotation.T + solid.position
    return StaticMesh(vertices, local.normals @ solid.rotation.T, local.triangles)


def merge(meshes: list[StaticMesh]) -> StaticMesh:
    """One mesh of several (triangle indices shifted)."""
    offsets = np.cumsum([0] + [len(m.vertices) for m in meshes[:-1]])
    return StaticMesh(
        np.concatenate([m.vertices for m in meshes]),
        np.concatenate([m.normals for m in meshes]),
        np.concatenate([m.triangles + o for m, o in zip(meshes, offsets, strict=True)]),
    )


def _flat(corners: np.ndarray, triangles: np.ndarray) -> StaticMesh:
    """Flat shading: three vertices of its own per triangle, its face normal on each."""
    vertices = corners[triangles].reshape(-1, 3)
    tri = vertices.reshape(-1, 3, 3)
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    normal /= np.maximum(np.linalg.norm(normal, axis=1, keepdims=True), 1e-12)
    return StaticMesh(
        vertices, np.repeat(normal, 3, axis=0), np.arange(len(vertices)).reshape(-1, 3)
    )


def _box(half: np.ndarray) -> StaticMesh:
    signs = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)
    corners = signs * half
    # corner index = 4 x + 2 y + z (0/1 per axis); two triangles per face, outward
    faces = [
        (0, 1, 3, 2),  # -x
        (4, 6, 7, 5),  # +x
        (0, 4, 5, 1),  # -y
        (2, 3, 7, 6),  # +y
        (0, 2, 6, 4),  # -z
        (1, 5, 7, 3),  # +z
    ]
    triangles = np.array([t for a, b, c, d in faces for t in ((a, b, c), (a, c, d))])
    return _flat(corners, triangles)


def _cylinder(radius: float, half: float) -> StaticMesh:
    n = CYLINDER_SEGMENTS
    angle = 2.0 * np.pi * np.arange(n) / n
    ring = np.stack([radius * np.cos(angle), radius * np.sin(angle)], axis=1)
    bottom = np.column_stack([ring, np.full(n, -half)])
    top = np.column_stack([ring, np.full(n, half)])
    corners = np.vstack([bottom, top, [[0, 0, -half], [0, 0, half]]])
    k = np.arange(n)
    nxt = (k + 1) % n
    sides = np.concatenate([np.stack([k, nxt, nxt + n], 1), np.stack([k, nxt + n, k + n], 1)])
    caps = np.concatenate(
        [
            np.stack([np.full(n, 2 * n), nxt, k], 1),
            np.stack([np.full(n, 2 * n + 1), k + n, nxt + n], 1),
        ]
    )
    side = _flat(corners, sides)
    # the side is round: its normals point out from the axis
    round_normals = side.vertices * [1.0, 1.0, 0.0]
    round_normals /= np.linalg.norm(round_normals, axis=1, keepdims=True)
    return merge([StaticMesh(side.vertices, round_normals, side.triangles), _flat(corners, caps)])


def _sphere(radius: float) -> StaticMesh:
    n, m = SPHERE_SEGMENTS, SPHERE_RINGS
    theta = np.pi * np.arange(m + 1) / m  # from the top
    phi = 2.0 * np.pi * np.arange(n + 1) / n
    t, p = np.meshgrid(theta, phi, indexing="ij")
    unit = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], axis=-1).reshape(
        -1, 3
    )
    r, c = np.meshgrid(np.arange(m), np.arange(n), indexing="ij")
    a = (r * (n + 1) + c).ravel()
    b, d, e = a + 1, a + n + 1, a + n + 2
    triangles = np.concatenate([np.stack([a, d, e], 1), np.stack([a, e, b], 1)])
    return StaticMesh(unit * radius, unit, triangles)


def _hull(points: np.ndarray) -> StaticMesh:
    from scipy.spatial import ConvexHull

    hull = ConvexHull(points)
    triangles = hull.simplices.copy()
    # orient every face outward (scipy's simplices are not consistently wound)
    tri = points[triangles]
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    flip = np.einsum("ij,ij->i", normal, hull.equations[:, :3]) < 0
    triangles[flip] = triangles[flip][:, ::-1]
    return _flat(points, triangles)
