"""The numba kernel of the reduced tier's show step: the full model's body poses from
many rows' joint angles at once (`physics.poses`), MuJoCo's `mj_kinematics` for the
bodies a creature is made of.

It does MuJoCo's arithmetic in MuJoCo's order (`mj_kinematics` in
engine_core_smooth.c and the quaternion helpers it calls: `mju_normalize4`,
`mju_mulQuat`, `mju_rotVecQuat`, `mju_axisAngle2Quat`, `mju_quat2Mat`,
`mju_mulMatVec3`, with their special cases, which decide signed zeros; MuJoCo 4.0.1
sums a quaternion's four products pairwise), so its poses are MuJoCo's bit for bit
(tests/physics/test_poses.py compares them with `mj_kinematics` on states a crowd
reaches; a state gone bad gives NaN where MuJoCo's does, whose sign bit may differ).
Only free and hinge joints; bodies with mocap or other joints are left to MuJoCo
(`physics.poses.PoseMap` says which).

Optional, as the other kernels are: `physics.poses` imports this module only when
numba is installed and steps MuJoCo's `mj_kinematics` row by row otherwise. One call
does every row of a share with the interpreter's lock released; MuJoCo's call computed
every body, geom and site of the full model (about 28 us a row, 150 bodies), this only
the creature's bodies' positions and orientations.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

MINVAL = 1e-15  # mjMINVAL


Quat = tuple[float, float, float, float]
Vec = tuple[float, float, float]


@njit(cache=True, nogil=True, inline="always")
def _normalize4(w: float, x: float, y: float, z: float) -> Quat:
    norm = math.sqrt((w * w + x * x) + (y * y + z * z))
    if norm < MINVAL:
        return 1.0, 0.0, 0.0, 0.0
    if abs(norm - 1.0) > MINVAL:
        inverse = 1.0 / norm
        return w * inverse, x * inverse, y * inverse, z * inverse
    return w, x, y, z


@njit(cache=True, nogil=True, inline="always")
def _mul_quat(a: Quat, b: Quat) -> Quat:
    return (
        (a[0] * b[0] - a[1] * b[1]) - (a[2] * b[2] + a[3] * b[3]),
        (a[0] * b[1] + a[1] * b[0]) + (a[2] * b[3] - a[3] * b[2]),
        (a[0] * b[2] - a[1] * b[3]) + (a[2] * b[0] + a[3] * b[1]),
        (a[0] * b[3] + a[1] * b[2]) + (a[3] * b[0] - a[2] * b[1]),
    )


@njit(cache=True, nogil=True, inline="always")
def _rot_vec_quat(v: Vec, q: Quat) -> Vec:
    if v[0] == 0 and v[1] == 0 and v[2] == 0:
        return 0.0, 0.0, 0.0
    if q[0] == 1 and q[1] == 0 and q[2] == 0 and q[3] == 0:
        return v
    t0 = q[0] * v[0] + q[2] * v[2] - q[3] * v[1]
    t1 = q[0] * v[1] + q[3] * v[0] - q[1] * v[2]
    t2 = q[0] * v[2] + q[1] * v[1] - q[2] * v[0]
    return (
        v[0] + 2 * (q[2] * t2 - q[3] * t1),
        v[1] + 2 * (q[3] * t0 - q[1] * t2),
        v[2] + 2 * (q[1] * t1 - q[2] * t0),
    )


@njit(cache=True, nogil=True, inline="always")
def _quat2mat(res: np.ndarray, k: int, q: Quat) -> None:
    """Row k of `res` (bodies, 9): MuJoCo's rotation matrix of `q`."""
    if q[0] == 1 and q[1] == 0 and q[2] == 0 and q[3] == 0:
        for i in range(9):
            res[k, i] = 0.0
        res[k, 0] = res[k, 4] = res[k, 8] = 1.0
        return
    q00, q01, q02, q03 = q[0] * q[0], q[0] * q[1], q[0] * q[2], q[0] * q[3]
    q11, q12, q13 = q[1] * q[1], q[1] * q[2], q[1] * q[3]
    q22, q23, q33 = q[2] * q[2], q[2] * q[3], q[3] * q[3]
    res[k, 0] = (q00 - q22) + (q11 - q33)
    res[k, 4] = (q00 + q22) - (q11 + q33)
    res[k, 8] = (q00 - q22) + (q33 - q11)
    res[k, 1] = 2 * (q12 - q03)
    res[k, 2] = 2 * (q13 + q02)
    res[k, 3] = 2 * (q12 + q03)
    res[k, 5] = 2 * (q23 - q01)
    res[k, 6] = 2 * (q13 - q02)
    res[k, 7] = 2 * (q23 + q01)


@njit(cache=True, nogil=True)
def body_poses(
    rows: np.ndarray,
    state: np.ndarray,
    qpos_start: int,
    parent: np.ndarray,
    free: np.ndarray,
    body_pos: np.ndarray,
    body_quat: np.ndarray,
    joint_start: np.ndarray,
    joint_qpos: np.ndarray,
    joint_axis: np.ndarray,
    joint_pos: np.ndarray,
    joint_qpos0: np.ndarray,
    xpos: np.ndarray,
    xquat: np.ndarray,
) -> None:
    """For each of `rows` r: the poses of the bodies (k = 0, 1, ... in MuJoCo's order,
    parents first) from the joint angles in state[r, qpos_start:], into xpos[r, k] and
    xquat[r, k]. Body k's parent is body parent[k] of these (-1: the world); free[k]:
    its one joint is free (qpos at joint_qpos[joint_start[k]]); else it sits at
    body_pos[k] / body_quat[k] in its parent and turns by the hinges
    joint_start[k]:joint_start[k + 1] (qpos, axis, anchor, qpos0)."""
    count = parent.shape[0]
    xmat = np.empty((count, 9))  # (scalars and tuples below: no array views per body)
    for r in rows:
        for k in range(count):
            if free[k]:
                a = qpos_start + joint_qpos[joint_start[k]]
                pos = (state[r, a], state[r, a + 1], state[r, a + 2])
                quat = _normalize4(state[r, a + 3], state[r, a + 4], state[r, a + 5],
                                   state[r, a + 6])  # fmt: skip
            else:
                p = parent[k]
                b = (body_pos[k, 0], body_pos[k, 1], body_pos[k, 2])
                bq = (body_quat[k, 0], body_quat[k, 1], body_quat[k, 2], body_quat[k, 3])
                if p >= 0:
                    pos = (
                        (xmat[p, 0] * b[0] + xmat[p, 1] * b[1] + xmat[p, 2] * b[2]) + xpos[r, p, 0],
                        (xmat[p, 3] * b[0] + xmat[p, 4] * b[1] + xmat[p, 5] * b[2]) + xpos[r, p, 1],
                        (xmat[p, 6] * b[0] + xmat[p, 7] * b[1] + xmat[p, 8] * b[2]) + xpos[r, p, 2],
                    )
                    parent_quat = (xquat[r, p, 0], xquat[r, p, 1], xquat[r, p, 2], xquat[r, p, 3])
                    quat = _mul_quat(parent_quat, bq)
                else:
                    pos, quat = b, bq
                for j in range(joint_start[k], joint_start[k + 1]):
                    # (MuJoCo's joint axis in the world, xaxis, is not needed here)
                    offset = (joint_pos[j, 0], joint_pos[j, 1], joint_pos[j, 2])
                    turned = _rot_vec_quat(offset, quat)
                    anchor = (turned[0] + pos[0], turned[1] + pos[1], turned[2] + pos[2])
                    angle = state[r, qpos_start + joint_qpos[j]] - joint_qpos0[j]
                    if angle == 0:
                        local = (1.0, 0.0, 0.0, 0.0)
                    else:
                        s = math.sin(angle * 0.5)
                        local = (math.cos(angle * 0.5), joint_axis[j, 0] * s,
                                 joint_axis[j, 1] * s, joint_axis[j, 2] * s)  # fmt: skip
                    quat = _mul_quat(quat, local)
                    vec = _rot_vec_quat(offset, quat)
                    pos = (anchor[0] - vec[0], anchor[1] - vec[1], anchor[2] - vec[2])
            quat = _normalize4(quat[0], quat[1], quat[2], quat[3])
            for i in range(3):
                xpos[r, k, i] = pos[i]
            for i in range(4):
                xquat[r, k, i] = quat[i]
            _quat2mat(xmat, k, quat)
