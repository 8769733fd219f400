"""The Hamilton product of quaternion arrays, with numpy alone: the one formula the
engine (`numeric.quaternions.quat_multiply`) and the Blender add-on (which carries this
file as `numeric_hamilton.py`, `blender_addon.shared`) both use. Quaternions are
(w, x, y, z). Reads and writes nothing but its arguments and result.
"""

from __future__ import annotations

import numpy as np


def multiply(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton products a * b of (..., 4) quaternions."""
    aw, ax, ay, az = np.moveaxis(a, -1, 0)
    bw, bx, by, bz = np.moveaxis(b, -1, 0)
    return np.stack(
        [
            aw * bw - ax * bx - ay * by - az * bz,
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
        ],
        axis=-1,
    )
