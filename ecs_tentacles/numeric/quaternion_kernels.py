"""The numba kernels of quaternion math: `quaternions.quat_rotate` for one quaternion per
vector (the sucker points' and the ground follow's case, a few times a frame: one pass,
where the numpy path's two cross products take some twenty array operations) and
`fur.vectors.quat_matrices` (the fur rig's mantle rotations, every frame: one pass for
some thirty array operations).

Optional, as the other kernels are: both use them only when numba is installed and fall
back to numpy otherwise. Both compute the same numbers bit for bit (the same operations
in the same order; tests/numeric/test_quaternions.py compares them).
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def rotate(q: np.ndarray, v: np.ndarray, out: np.ndarray) -> None:
    """`out[i]`: vector `v[i]` (n, 3) rotated by unit quaternion `q[i]` (n, 4; w, x, y,
    z): t = 2 u x v, v + w t + u x t (u the quaternion's vector part)."""
    for i in range(len(q)):
        w, x, y, z = q[i, 0], q[i, 1], q[i, 2], q[i, 3]
        v0, v1, v2 = v[i, 0], v[i, 1], v[i, 2]
        t0 = 2.0 * (y * v2 - z * v1)
        t1 = 2.0 * (z * v0 - x * v2)
        t2 = 2.0 * (x * v1 - y * v0)
        out[i, 0] = v0 + w * t0 + (y * t2 - z * t1)
        out[i, 1] = v1 + w * t1 + (z * t0 - x * t2)
        out[i, 2] = v2 + w * t2 + (x * t1 - y * t0)


@njit(cache=True, nogil=True)
def matrices(quat: np.ndarray, out: np.ndarray) -> None:
    """`out[i]` (n, 3, 3): the rotation matrix of unit quaternion `quat[i]` (w, x, y, z),
    term by term as `fur.vectors.quat_matrices`'s numpy path forms it."""
    for i in range(len(quat)):
        w, x, y, z = quat[i, 0], quat[i, 1], quat[i, 2], quat[i, 3]
        xx, yy, zz = x * x, y * y, z * z
        xy, xz, yz = x * y, x * z, y * z
        wx, wy, wz = w * x, w * y, w * z
        out[i, 0, 0], out[i, 0, 1], out[i, 0, 2] = 1 - 2 * (yy + zz), 2 * (xy - wz), 2 * (xz + wy)
        out[i, 1, 0], out[i, 1, 1], out[i, 1, 2] = 2 * (xy + wz), 1 - 2 * (xx + zz), 2 * (yz - wx)
        out[i, 2, 0], out[i, 2, 1], out[i, 2, 2] = 2 * (xz - wy), 2 * (yz + wx), 1 - 2 * (xx + yy)
