"""The rig's math: every guide's result frame from its bind pose and its control.

Vectors are float32 arrays of shape (3, n) (one row per axis), so every step is a few
whole-array operations. Per guide, in the mantle's local frame (thesis 3.2, 4.3):

1. direction and aim: the rest direction, the *direction* target (the rest direction
   reaching `reach` metres plus the control's offset from its rest position) and the
   *aim* target (root -> control) are blended with weights ``1 - aim - direction``
   (at least 0), `direction`, `aim`, as a normalised weighted sum on the unit sphere;
2. lift: the result turns along the great circle toward the surface normal by the
   fraction `lift` of the angle (lift 1 is the normal);
3. random twist: it turns about the normal (the follicle axis) by
   ``random * twist_max * multiplier`` (the multiplier fixed per guide at generation).

No flipping: every target is clamped into the guide's outer cap (at least
`min_elevation` above the skin; for a bent guide, more, so its whole curve stays out)
by a continuous map, and a weighted sum of vectors in a cap stays in it, so a result
can neither enter the surface nor jump when controls move or cross; the guide's frame
is carried by the minimal rotation from its rest direction (never antipodal inside the
cap), then twisted. Finally the frame goes to world space by the body's pose and each
guide's rest shape (rest-frame coordinates, homogeneous) is posed by one batched
matrix product.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

F32 = np.float32
TINY = 1e-12


@dataclass
class Bind:
    """The rig's bind pose of n guides (float32, body-local, vectors as (3, n))."""

    root: np.ndarray
    normal: np.ndarray
    rest: np.ndarray  # unit, inside the guide's cap
    side: np.ndarray  # unit, normal x rest
    tan_min: np.ndarray  # (n,) tan of the lowest elevation allowed
    multiplier: np.ndarray  # (n,)
    control: np.ndarray  # (n,) control row
    body: np.ndarray  # (n,) index into the bodies passed to `frames`
    shape_h: np.ndarray  # (n, points, 4): rest-frame coordinates and a 1

    def __len__(self) -> int:
        return len(self.control)


@dataclass
class ControlValues:
    """Effective per-control values (float32): weights, twist angle, targets (3, n_controls)."""

    lift: np.ndarray
    aim: np.ndarray
    direction: np.ndarray
    twist: np.ndarray  # radians for a multiplier of 1
    position: np.ndarray  # creature frame
    offset: np.ndarray  # (position - rest position) / reach


def dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise dot product of (3, n) arrays."""
    result: np.ndarray = a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
    return result


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise cross product of (3, n) arrays."""
    out = np.empty(np.broadcast_shapes(a.shape, b.shape), dtype=np.result_type(a, b))
    np.subtract(a[1] * b[2], a[2] * b[1], out=out[0])
    np.subtract(a[2] * b[0], a[0] * b[2], out=out[1])
    np.subtract(a[0] * b[1], a[1] * b[0], out=out[2])
    return out


def normalize(v: np.ndarray) -> np.ndarray:
    """Unit vectors of (3, n) `v` (zero vectors stay zero)."""
    result: np.ndarray = v / np.maximum(np.sqrt(dot(v, v)), TINY)
    return result


def clamp_to_cap(v: np.ndarray, normal: np.ndarray, tan_min: np.ndarray) -> np.ndarray:
    """Unit vectors `v` moved continuously into the caps elevation >= atan(tan_min).

    The normal component is raised to at least `tan_min` and the result normalised:
    unchanged inside the cap (up to a sliver of width tan - sin of the bound), a vector
    below it keeps its azimuth, and -normal goes smoothly to +normal: no jumps anywhere.
    """
    h = dot(v, normal)
    lifted = np.maximum(h, tan_min)
    return normalize(v + (lifted - h) * normal)


def slerp_to_normal(d: np.ndarray, normal: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Turn unit `d` toward `normal` by the fraction `t` of the angle between them."""
    cos = np.clip(dot(d, normal), -1.0, 1.0)
    angle = np.arccos(cos)
    sin = np.sin(angle)
    near = sin < 1e-6
    safe = np.where(near, F32(1.0), sin)
    a = np.where(near, 1.0 - t, np.sin((1.0 - t) * angle) / safe)
    b = np.where(near, t, np.sin(t * angle) / safe)
    result: np.ndarray = a * d + b * normal
    return result


def rotate_minimal(a: np.ndarray, b: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Rotate `x` by the smallest rotation taking unit `a` to unit `b` (a != -b)."""
    c = dot(a, b)
    k = cross(a, b)
    result: np.ndarray = c * x + cross(k, x) + k * (dot(k, x) / np.maximum(1.0 + c, 1e-7))
    return result


def rotate_about(axis: np.ndarray, angle: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Rotate `x` about unit `axis` by `angle` radians (right hand)."""
    cos, sin = np.cos(angle), np.sin(angle)
    result: np.ndarray = cos * x + sin * cross(axis, x) + ((1.0 - cos) * dot(axis, x)) * axis
    return result


def quat_matrices(quat: np.ndarray) -> np.ndarray:
    """Rotation matrices (n, 3, 3) of unit quaternions (n, 4) (w, x, y, z)."""
    w, x, y, z = quat.T
    return np.stack(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    ).transpose(2, 0, 1)


def local_frames(bind: Bind, values: ControlValues) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Result axis, up and side unit vectors (3, n), body-local, of every guide."""
    ctrl = bind.control
    rest, normal = bind.rest, bind.normal
    direction = rest
    aim_w = values.aim[ctrl]
    dir_w = values.direction[ctrl]
    if values.aim.any() or values.direction.any():
        total = rest * np.maximum(1.0 - aim_w - dir_w, 0.0)
        if values.direction.any():
            target = normalize(rest + values.offset[:, ctrl])
            total += dir_w * clamp_to_cap(target, normal, bind.tan_min)
        if values.aim.any():
            target = normalize(values.position[:, ctrl] - bind.root)
            total += aim_w * clamp_to_cap(target, normal, bind.tan_min)
        direction = normalize(total)
    if values.lift.any():
        direction = slerp_to_normal(direction, normal, values.lift[ctrl])
    side = bind.side if direction is rest else rotate_minimal(rest, direction, bind.side)
    if values.twist.any():
        angle = values.twist[ctrl] * bind.multiplier
        direction = rotate_about(normal, angle, direction)
        side = rotate_about(normal, angle, side)
    return direction, cross(side, direction), side


def world_frames(
    bind: Bind,
    local: tuple[np.ndarray, np.ndarray, np.ndarray],
    rotation: np.ndarray,
    position: np.ndarray,
    out: np.ndarray,
) -> np.ndarray:
    """Write the frames to world space into `out` (n, 4, 3): axis, up, side, root rows.

    `rotation` (n_bodies, 3, 3) and `position` (n_bodies, 3) are the bodies' poses;
    `bind.body` picks each guide's.
    """
    if len(rotation) == 1:  # one body: plain numbers, no per-guide gather
        rot = [[F32(rotation[0, i, j]) for j in range(3)] for i in range(3)]
        pos = [F32(position[0, i]) for i in range(3)]
    else:
        gathered = rotation.astype(F32).reshape(-1, 9).T[:, bind.body]
        rot = [[gathered[3 * i + j] for j in range(3)] for i in range(3)]
        moved = position.astype(F32).T[:, bind.body]
        pos = [moved[i] for i in range(3)]
    for slot, vec in enumerate((*local, bind.root)):
        for i in range(3):
            row = out[:, slot, i]
            np.multiply(vec[0], rot[i][0], out=row)
            row += vec[1] * rot[i][1]
            row += vec[2] * rot[i][2]
            if slot == 3:
                row += pos[i]
    return out


def pose(shape_h: np.ndarray, frames: np.ndarray, out: np.ndarray) -> np.ndarray:
    """World points (n, points, 3) = rest-frame coordinates x world frame, batched."""
    return np.matmul(shape_h, frames, out=out)
