"""Row-wise vector helpers of the rig: (3, n) arrays, one row per axis."""

from __future__ import annotations

import numpy as np

from ecs_tentacles.numeric.quaternions import KERNELS as QUATERNIONS

TINY = 1e-12


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
    """Unit vectors `v` (3, n) moved continuously into the caps elevation >= atan(tan_min).

    The normal component is raised to at least `tan_min` and the result normalised:
    unchanged inside the cap (up to a sliver of width tan - sin of the bound), a vector
    below it keeps its azimuth, and -normal goes smoothly to +normal: no jumps anywhere.
    """
    h = dot(v, normal)
    return normalize(v + (np.maximum(h, tan_min) - h) * normal)


def quat_matrices(quat: np.ndarray) -> np.ndarray:
    """Rotation matrices (n, 3, 3) of unit quaternions (n, 4) (w, x, y, z); by one numba
    pass when numba is installed (the same numbers: `numeric.quaternion_kernels`)."""
    if quat.dtype == np.float64 and quat.ndim == 2 and (fast := QUATERNIONS.get()) is not None:
        matrices = np.empty((len(quat), 3, 3))
        fast.matrices(quat, matrices)
        return matrices
    w, x, y, z = quat.T
    xx, yy, zz = x * x, y * y, z * z
    xy, xz, yz = x * y, x * z, y * z
    wx, wy, wz = w * x, w * y, w * z
    out = np.empty((len(quat), 3, 3), dtype=quat.dtype if quat.dtype.kind == "f" else float)
    out[:, 0, 0], out[:, 0, 1], out[:, 0, 2] = 1 - 2 * (yy + zz), 2 * (xy - wz), 2 * (xz + wy)
    out[:, 1, 0], out[:, 1, 1], out[:, 1, 2] = 2 * (xy + wz), 1 - 2 * (xx + zz), 2 * (yz - wx)
    out[:, 2, 0], out[:, 2, 1], out[:, 2, 2] = 2 * (xz - wy), 2 * (yz + wx), 1 - 2 * (xx + yy)
    return out
