"""Triangle meshes of the terrain's ground (`TerrainGround.meshes`), for drawing and export.

    for part in ground_meshes(field, solids):   # GroundMesh: name, mesh, rgb, grid, recorded
        ...

"terrain" is the heightfield's surface, triangulated exactly as MuJoCo collides with it
(each cell split along its (i, j) - (i + 1, j + 1) diagonal), with smooth normals;
"obstacles" is every obstacle in one mesh (boxes, cylinders, spheres, the convex pieces of
mesh obstacles), flat-shaded. World coordinates, metres, counter-clockwise from outside.
The plane has neither (the renderer draws its grid; exporters write no ground).
"beyond" (`beyond_mesh`): past a heightfield's edge the physics has a plane at the
field's lowest height (`BEYOND_DROP` under it); it is drawn as a wide square ring round
the field, `REACH` m out, with a gentle bank from the field's border down to it, so the
terrain reads as a piece of a wider shore, not a sheet in the air. (The bank is drawn
only: in the physics the field's edge is a step down.)
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ecs_tentacles.ground import GroundMesh, StaticMesh
from ecs_tentacles.terrain.heightfield import BEYOND_DROP, Heightfield
from ecs_tentacles.terrain.shapes import Solid

# how the sandbox and the exporters colour them (rgb 0..1): sand and earth, grey rock
COLOURS = {"terrain": (0.62, 0.56, 0.44), "obstacles": (0.50, 0.50, 0.52)}
REACH = 4000.0  # m from the origin to the outer edge of the ground beyond the field
BANK_SLOPE = 0.2  # rise over run of the bank from the field's highest border point
BANK_MIN = 0.5  # m: the bank's least width
CYLINDER_SEGMENTS = 24
SPHERE_SEGMENTS, SPHERE_RINGS = 24, 12


def ground_meshes(field: Heightfield | None, solids: Sequence[Solid]) -> list[GroundMesh]:
    """The meshes of a ground: the heightfield's surface ("terrain", with the sandbox's
    grid), the ground beyond its edge ("beyond": drawn, not recorded) and the obstacles
    ("obstacles"); those it has, in that order."""
    out = []
    if field is not None:
        out.append(GroundMesh("terrain", heightfield_mesh(field), COLOURS["terrain"], 1.0))
        beyond = beyond_mesh(field)
        out.append(GroundMesh("beyond", beyond, COLOURS["terrain"], 0.0, recorded=False))
    if solids:
        merged = merge([solid_mesh(s) for s in solids])
        out.append(GroundMesh("obstacles", merged, COLOURS["obstacles"], 0.0))
    return out


def heightfield_mesh(field: Heightfield) -> StaticMesh:
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


def beyond_mesh(field: Heightfield) -> StaticMesh:
    """The plane past the heightfield's edge (a square ring out to `REACH`) and a bank
    from the field's border down to it (`BANK_SLOPE`)."""
    a, b = 0.5 * field.size[0], 0.5 * field.size[1]
    low = float(field.heights.min()) - BEYOND_DROP
    heights = field.heights  # rows along y, columns along x
    rows, cols = heights.shape
    run = BANK_MIN + float(heights.max() - low) / BANK_SLOPE  # the bank's width
    x, y = np.linspace(-a, a, cols), np.linspace(-b, b, rows)
    # each border walked counter-clockwise seen from above, with its outward direction
    borders = [
        (np.stack([x, np.full(cols, -b)], 1), heights[0, :], (0.0, -1.0)),
        (np.stack([np.full(rows, a), y], 1), heights[:, -1], (1.0, 0.0)),
        (np.stack([x[::-1], np.full(cols, b)], 1), heights[-1, ::-1], (0.0, 1.0)),
        (np.stack([np.full(rows, -a), y[::-1]], 1), heights[::-1, 0], (-1.0, 0.0)),
    ]
    parts = [_bank(xy, top, low, np.array(out), run) for xy, top, out in borders]
    corners = np.array([[-a, -b], [a, -b], [a, b], [-a, b]])
    for k in range(4):  # the bank round each corner: the corner down to three points
        out_in, out_next = np.array(borders[k - 1][2]), np.array(borders[k][2])
        corner = corners[k]
        top = float(borders[k][1][0])
        points = [corner, corner + run * out_in, corner + run * (out_in + out_next)]
        points.append(corner + run * out_next)
        zs = [top, low, low, low]
        vertices = np.array([[*xy, z] for xy, z in zip(points, zs, strict=True)])
        normal = np.array([*(out_in + out_next) * (top - low) / run, 1.0])
        normals = np.tile(normal / np.linalg.norm(normal), (4, 1))
        parts.append(StaticMesh(vertices, normals, np.array([[0, 1, 2], [0, 2, 3]])))
    # the ring: inner corners 0-3 (the bank's foot), outer corners 4-7, counter-clockwise
    foot = corners * (1.0 + run / np.array([a, b]))
    outer = np.array([[-REACH, -REACH], [REACH, -REACH], [REACH, REACH], [-REACH, REACH]])
    ring = np.hstack([np.vstack([foot, outer]), np.full((8, 1), low)])
    faces = []
    for k in range(4):
        i0, i1, o0, o1 = k, (k + 1) % 4, 4 + k, 4 + (k + 1) % 4
        faces += [[o0, o1, i1], [o0, i1, i0]]
    parts.append(StaticMesh(ring, np.tile([0.0, 0.0, 1.0], (8, 1)), np.array(faces)))
    offsets = np.cumsum([0] + [len(m.vertices) for m in parts[:-1]])
    return StaticMesh(
        np.concatenate([m.vertices for m in parts]),
        np.concatenate([m.normals for m in parts]),
        np.concatenate([m.triangles + o for m, o in zip(parts, offsets, strict=True)]),
    )


def _bank(
    xy: np.ndarray, top: np.ndarray, low: float, outward: np.ndarray, run: float
) -> StaticMesh:
    """A slope from the border points `xy` (n, 2) at heights `top` down to `low`, `run` m
    out along `outward` (the points run counter-clockwise seen from above)."""
    n = len(xy)
    upper = np.hstack([xy, top[:, None]])
    lower = np.hstack([xy + run * outward, np.full((n, 1), low)])
    vertices = np.vstack([upper, lower])  # upper k, lower n + k
    k = np.arange(n - 1)
    triangles = np.concatenate(
        [np.stack([n + k, n + k + 1, k + 1], 1), np.stack([n + k, k + 1, k], 1)]
    )
    normals = np.hstack([np.outer((top - low) / run, outward), np.ones((n, 1))])
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    return StaticMesh(vertices, np.vstack([normals, normals]), triangles)
