"""What sits on and under the creatures: soft blob shadows on the ground and sucker discs.

* Shadows: a dark, soft-edged disc on the ground under each mantle and each link (the
  key light is nearly overhead, so a blob reads as its shadow), fading as the body rises
  and sized from it. On terrain a blob lies at the topmost surface under its body.
  Software GL cannot afford a shadow map for thousands of bodies; a blob costs one
  instanced quad (`shadow_instances`; one draw for every creature).
* Suckers: a flat disc on the underside of each sucker's link, pale when free and dark
  rose when gripping (`sucker_instances`; one draw, the cylinder template).

Reads: the Transform store (interpolated poses), the Sucker store, link and mantle
sizes, the world's `Ground`. Writes nothing.
"""

from __future__ import annotations

import numpy as np

from ecs_tentacles.ground import Ground
from ecs_tentacles.numeric.quaternions import quat_rotate
from ecs_tentacles.render.gpu import INSTANCE_FLOATS
from ecs_tentacles.render.meshes import Mesh, cylinder

SHADOW_LIFT = 0.004  # metres above the ground a blob is drawn (over the surface)
SHADOW_FADE = 0.5  # metres above the ground at which a body's blob is gone
SHADOW_ALPHA = 0.5  # darkness of a blob under a body resting on the ground
SHADOW_GROW = 2.4  # a blob's radius, in its body's radii
SUCKER_SCALE = 0.55  # a disc's radius, as a share of its link's radius
SUCKER_THICKNESS = 0.0015  # metres (half)
SUCKER_FREE = (0.97, 0.80, 0.78, 1.0)
SUCKER_GRIP = (0.55, 0.16, 0.22, 1.0)

SUCKER_DISC = cylinder(8)  # small: eight sides read as round, and crowds have thousands
QUAD = Mesh(  # the unit square on z = 0, seen from above counter-clockwise
    positions=np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], np.float32),
    normals=np.tile(np.array([0, 0, 1], np.float32), (4, 1)),
    sides=np.zeros(4, np.float32),
    indices=np.array([0, 1, 2, 0, 2, 3], np.uint32),
)


def shadow_instances(
    ground: Ground, centres: np.ndarray, radii: np.ndarray, light: np.ndarray
) -> np.ndarray:
    """Instance rows (n, INSTANCE_FLOATS) of the blobs under bodies at `centres` (n, 3)
    of `radii` (n,), cast away from the unit `light` direction (towards the light)."""
    n = len(centres)
    rows = np.zeros((n, INSTANCE_FLOATS), np.float32)
    floor = ground.surface(centres[:, :2]) if not ground.flat else np.zeros(n)
    above = np.maximum(centres[:, 2] - floor, 0.0)
    height = np.maximum(above - radii, 0.0)
    fade = np.clip(1.0 - height / SHADOW_FADE, 0.0, 1.0)
    rows[:, 0:2] = centres[:, :2] - above[:, None] * light[:2] / max(light[2], 0.2)
    rows[:, 2] = floor + SHADOW_LIFT
    rows[:, 3:7] = (1.0, 0.0, 0.0, 0.0)
    size = SHADOW_GROW * radii * (1.0 + 2.0 * height)
    rows[:, 7], rows[:, 8], rows[:, 9], rows[:, 10] = size, size, 1.0, 0.0
    rows[:, 11:14] = 0.0
    rows[:, 14] = SHADOW_ALPHA * fade
    return rows


def sucker_instances(
    pos: np.ndarray,
    quat: np.ndarray,
    link_rows: np.ndarray,
    offsets: np.ndarray,
    radii: np.ndarray,
    attached: np.ndarray,
) -> np.ndarray:
    """Instance rows of the sucker discs: centred on each sucker point, flat against its
    link's underside (the cylinder template's axis along the link's z)."""
    n = len(link_rows)
    rows = np.zeros((n, INSTANCE_FLOATS), np.float32)
    if not n:
        return rows
    q = quat[link_rows]
    rows[:, 0:3] = pos[link_rows] + quat_rotate(q, offsets)
    rows[:, 3:7] = q
    rows[:, 7] = rows[:, 8] = SUCKER_SCALE * radii
    rows[:, 9] = SUCKER_THICKNESS
    rows[:, 11:15] = np.where(attached[:, None], SUCKER_GRIP, SUCKER_FREE)
    return rows
