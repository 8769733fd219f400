"""What lies round the scene: the ground beyond a heightfield out to the horizon, the
sky's colours and the distance fog that joins them.

Past a heightfield's edge the physics has a plane at the field's lowest height
(`ecs_tentacles.ground`, `BEYOND_DROP` under it); `beyond_mesh` draws that plane as a
wide square ring round the field, `REACH` m out, and a gentle bank from the field's
border down to it, so the terrain reads as a piece of a wider shore and not a sheet in
the air. (The bank is drawn only: in the physics the field's edge is a step down, and a
creature past it stands on the plane, under the bank's picture.)
The renderer appends it to the terrain's mesh (same colour and shader, no extra draw).
Fog starts a little past the point the camera looks at and is complete well before the
far plane, in the sky's horizon colour, so the plane's far edge is never seen.
"""

from __future__ import annotations

import numpy as np

from ecs_tentacles.ground import BEYOND_DROP, Ground
from ecs_tentacles.ground.meshes import StaticMesh

REACH = 4000.0  # m from the origin to the outer edge of the ground beyond the field
HORIZON = (0.78, 0.82, 0.85)  # the sky at the horizon, and the fog's colour
ZENITH = (0.36, 0.53, 0.76)  # the sky straight up
BANK_SLOPE = 0.2  # rise over run of the bank from the field's highest border point
BANK_MIN = 0.5  # m: the bank's least width
FOG_START = 1.5  # fog begins this many camera distances from the eye
FOG_END = 14.0  # and is complete at this many (at least FOG_END_MIN m)
FOG_END_MIN = 40.0


def fog_range(distance: float) -> tuple[float, float]:
    """(start, end) of the fog in metres from the eye, for a camera `distance` m from the
    point it looks at."""
    end = max(FOG_END * distance, FOG_END_MIN)
    return min(FOG_START * distance, 0.5 * end), end


def beyond_mesh(ground: Ground) -> StaticMesh | None:
    """The plane past the heightfield's edge (a square ring out to `REACH`) and a bank
    from the field's border down to it (`BANK_SLOPE`); None without a heightfield."""
    field = ground.heightfield
    if field is None:
        return None
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
