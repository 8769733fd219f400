"""The numba kernel of gait-clip replay: `GaitClips.evaluate` for K creatures in one pass.

Optional, as the fur rig's kernels are: `clips` imports this module only when numba is
installed (the ``dev`` extra brings it) and falls back to its whole-array numpy path
otherwise; both give the same poses to float64 rounding (tests/lod/test_clips.py).

The numpy path makes about twenty passes over (creatures, bodies) arrays (gather the
clip frame, interpolate, normalise, turn and move); at 10,000 kinematic creatures of
81 bodies that was about 60 ms a frame. Here each body is read once and written once.
Compiled on first use and cached on disk (``cache=True``).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def place(
    pose: np.ndarray,
    change: np.ndarray,
    row: np.ndarray,
    fraction: np.ndarray,
    interpolate: bool,
    xy: np.ndarray,
    heading: np.ndarray,
    out_rows: np.ndarray,
    out_pos: np.ndarray,
    out_quat: np.ndarray,
) -> None:
    """Creature k shows clip table row `row[k]` (+ `fraction[k]` of `change` when
    `interpolate`, quaternions renormalised) moved to `xy[k]` and turned by `heading[k]`,
    written to row `out_rows[k]` of the outputs (a batch's pose arrays: no copy after).

    `pose` and `change` are (rows, B, 7) ground-frame tables (position, quaternion);
    the outputs are (N, B, 3) and (N, B, 4).
    """
    for k in range(len(row)):
        r = row[k]
        o = out_rows[k]
        t = fraction[k]
        c, s = math.cos(heading[k]), math.sin(heading[k])
        hc, hs = math.cos(0.5 * heading[k]), math.sin(0.5 * heading[k])
        ox, oy = xy[k, 0], xy[k, 1]
        for b in range(pose.shape[1]):
            p = pose[r, b]
            x, y, z = p[0], p[1], p[2]
            w, qx, qy, qz = p[3], p[4], p[5], p[6]
            if interpolate:
                d = change[r, b]
                x, y, z = x + d[0] * t, y + d[1] * t, z + d[2] * t
                w, qx, qy, qz = w + d[3] * t, qx + d[4] * t, qy + d[5] * t, qz + d[6] * t
                norm = math.sqrt(w * w + qx * qx + qy * qy + qz * qz)
                w, qx, qy, qz = w / norm, qx / norm, qy / norm, qz / norm
            out_pos[o, b, 0] = c * x - s * y + ox
            out_pos[o, b, 1] = s * x + c * y + oy
            out_pos[o, b, 2] = z
            out_quat[o, b, 0] = hc * w - hs * qz
            out_quat[o, b, 1] = hc * qx - hs * qy
            out_quat[o, b, 2] = hc * qy + hs * qx
            out_quat[o, b, 3] = hc * qz + hs * w
