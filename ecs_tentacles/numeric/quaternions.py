"""Vectorised quaternion helpers; quaternions are (w, x, y, z) like MuJoCo's."""

from __future__ import annotations

import numpy as np

from ecs_tentacles.numeric.hamilton import multiply
from ecs_tentacles.numeric.optional_kernels import OptionalKernels

# numba's kernel when installed (the same numbers bit for bit; "numpy": never)
KERNELS = OptionalKernels("ecs_tentacles.numeric.quaternion_kernels", "ECS_TENTACLES_QUATERNIONS")


def quat_about_z(angle: np.ndarray | float) -> np.ndarray:
    """Unit quaternions rotating by `angle` radians about +z; shape (..., 4)."""
    half = 0.5 * np.asarray(angle, dtype=np.float64)
    out = np.zeros((*half.shape, 4))  # (filled in place: `np.stack` was most of a call)
    out[..., 0] = np.cos(half)
    out[..., 3] = np.sin(half)
    return out


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """`np.cross(a, b)` of (..., 3) arrays: the same products and differences, without
    the general function's bookkeeping (four times the arithmetic for small arrays)."""
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    return np.stack([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0], axis=-1)


def quat_rotate(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Rotate vectors `v` (..., 3) by unit quaternions `q` (..., 4)."""
    if (
        isinstance(v, np.ndarray)
        and q.ndim == v.ndim == 2
        and len(q) == len(v)
        and q.dtype == v.dtype == np.float64
        and (fast := KERNELS.get()) is not None
    ):  # one quaternion per vector: one pass
        out = np.empty((len(q), 3))
        fast.rotate(q, v, out)
        return out
    w = q[..., :1]
    u = q[..., 1:]
    t = 2.0 * cross(u, v)
    return np.asarray(v + w * t + cross(u, t))


quat_multiply = multiply  # Hamilton product a * b of quaternion arrays (..., 4)
