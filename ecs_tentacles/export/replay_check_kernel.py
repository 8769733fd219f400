"""The numba kernel of a recorder's replay check: whether the take's reconstruction of K
replayed creatures (`take.replay.blend` then `place`) lands within the tolerance of the
poses the world shows, in one pass that reads each body once and builds no arrays.

Optional, as the other kernels are: `export.replay_recording` imports this module only
when numba is installed and otherwise reconstructs the poses with numpy; both compute
the same numbers to float64 rounding (tests/export/test_replay_check.py). The numpy
path made a dozen passes over (creatures, bodies, 7) arrays: about 14 ms of every
recorded frame of the 1,024 crowd, a tenth of a bake.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def replay_within(
    pose: np.ndarray,
    idle_frames: int,
    crawl_frames: int,
    kind: np.ndarray,
    phase: np.ndarray,
    xy: np.ndarray,
    heading: np.ndarray,
    store: np.ndarray,
    world_pos: np.ndarray,
    world_quat: np.ndarray,
    tolerance: float,
    rotation: float,
) -> np.ndarray:
    """Per creature k: clip `pose` ((F_idle + F_crawl, B, 7), ground frame) of `kind[k]`
    at `phase[k]`, placed at `xy[k]` turned by `heading[k]`, against the world's rows
    `store[k]` (B,) of `world_pos` / `world_quat`: every position within `tolerance` (m,
    per axis) and every rotation's 1 - |q . q'| within `rotation`."""
    out = np.zeros(len(kind), dtype=np.bool_)
    for k in range(len(kind)):
        count = crawl_frames if kind[k] == 1 else idle_frames
        offset = idle_frames if kind[k] == 1 else 0
        below = math.floor(phase[k])
        t = phase[k] - below
        here = offset + int(below) % count
        after = offset + (int(below) + 1) % count
        c, s = math.cos(heading[k]), math.sin(heading[k])
        hc, hs = math.cos(0.5 * heading[k]), math.sin(0.5 * heading[k])
        ox, oy = xy[k, 0], xy[k, 1]
        good = True
        for b in range(pose.shape[1]):
            p, q = pose[here, b], pose[after, b]
            sign = 1.0
            if p[3] * q[3] + p[4] * q[4] + p[5] * q[5] + p[6] * q[6] < 0.0:
                sign = -1.0
            x = p[0] + (q[0] - p[0]) * t
            y = p[1] + (q[1] - p[1]) * t
            z = p[2] + (q[2] - p[2]) * t
            w = p[3] + (sign * q[3] - p[3]) * t
            qx = p[4] + (sign * q[4] - p[4]) * t
            qy = p[5] + (sign * q[5] - p[5]) * t
            qz = p[6] + (sign * q[6] - p[6]) * t
            norm = math.sqrt(w * w + qx * qx + qy * qy + qz * qz)
            w, qx, qy, qz = w / norm, qx / norm, qy / norm, qz / norm
            row = store[k, b]
            wp = world_pos[row]
            if (
                abs(c * x - s * y + ox - wp[0]) > tolerance
                or abs(s * x + c * y + oy - wp[1]) > tolerance
                or abs(z - wp[2]) > tolerance
            ):
                good = False
                break
            wq = world_quat[row]
            dot = (
                (hc * w - hs * qz) * wq[0]
                + (hc * qx - hs * qy) * wq[1]
                + (hc * qy + hs * qx) * wq[2]
                + (hc * qz + hs * w) * wq[3]
            )
            if 1.0 - abs(dot) > rotation:
                good = False
                break
        out[k] = good
    return out
