"""Ground frames: poses relative to a point on the ground and a heading, and back.

A ground frame has its origin on the ground plane (z = 0) at `xy` and its x axis along
`heading` (yaw, radians, counter-clockwise about +z). Moving a pose into it removes
the heading's yaw; roll, pitch and height are kept. Everything is vectorised over
leading axes; quaternions are (w, x, y, z) like MuJoCo's. Reads and writes nothing
but its arguments (and `out` arrays where given).
"""

from __future__ import annotations

import numpy as np


def to_ground(
    pos: np.ndarray, quat: np.ndarray, xy: np.ndarray, heading: np.ndarray | float
) -> tuple[np.ndarray, np.ndarray]:
    """World poses `pos` (..., B, 3) / `quat` (..., B, 4) in the ground frames (xy (..., 2),
    heading (...))."""
    heading = np.asarray(heading, dtype=np.float64)
    shifted = np.array(pos, dtype=np.float64)
    shifted[..., :2] -= np.asarray(xy, dtype=np.float64)[..., None, :]
    return rotate_z(shifted, -heading[..., None]), yaw_times(-heading[..., None], quat)


def rotate_z(v: np.ndarray, angle: np.ndarray | float) -> np.ndarray:
    """Vectors `v` (..., 3) rotated by `angle` (broadcast against v[..., 0]) about +z."""
    angle = np.asarray(angle, dtype=np.float64)
    c, s = np.cos(angle), np.sin(angle)
    out = np.array(v, dtype=np.float64)
    out[..., 0] = c * v[..., 0] - s * v[..., 1]
    out[..., 1] = s * v[..., 0] + c * v[..., 1]
    return out


def yaw_times(angle: np.ndarray | float, quat: np.ndarray) -> np.ndarray:
    """The rotation about +z by `angle` composed before `quat`: q_z(angle) * quat."""
    half = 0.5 * np.asarray(angle, dtype=np.float64)
    c, s = np.cos(half), np.sin(half)
    q = np.asarray(quat, dtype=np.float64)
    w, x, y, z = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    return np.stack([c * w - s * z, c * x - s * y, c * y + s * x, c * z + s * w], axis=-1)


def nlerp(a: np.ndarray, b: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Normalised linear interpolation of unit quaternions, the shorter way round.

    `t` broadcasts against a[..., 0]."""
    sign = np.where(np.sum(a * b, axis=-1) < 0.0, -1.0, 1.0)
    t = np.asarray(t, dtype=np.float64)
    q = a * (1.0 - t)[..., None] + b * (sign * t)[..., None]
    unit: np.ndarray = q / np.linalg.norm(q, axis=-1, keepdims=True)
    return unit


def quat_power(q: np.ndarray, s: np.ndarray) -> np.ndarray:
    """The unit quaternion `q` (4,) raised to the powers `s` (N,): the same axis, s x the
    angle (the shorter way round); shape (N, 4)."""
    q = q if q[0] >= 0.0 else -q
    sine = float(np.linalg.norm(q[1:]))
    half = float(np.arctan2(sine, q[0]))
    axis = q[1:] / sine if sine > 0.0 else np.zeros(3)
    angle = np.asarray(s, dtype=np.float64) * half
    return np.concatenate([np.cos(angle)[:, None], np.sin(angle)[:, None] * axis], axis=1)
