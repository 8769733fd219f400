"""The numba kernel of a frame's control values and table (`rig.control_plan`).

Optional, as the rig's other kernels are: `rig` imports this module only when numba
is installed and `ECS_TENTACLES_RIG` is not "numpy". It computes exactly what
`bind.control_values` and `rig.control_table` compute (the same float64 operations,
then the same float32 ones, in the same order; tests/fur/test_control_kernels.py
compares them bit for bit) in one pass over the controls instead of about thirty
numpy passes over a dozen values each: right after the physics step, with the
caches cold, those took about 60 us a frame.
"""

from __future__ import annotations

import numpy as np
from numba import njit

F32 = np.float32
LIFT, AIM, DIRECTION, RANDOM, DYNAMIC = range(5)  # `bind`'s behaviour columns
UNLIFT, KEEP, TWIST, TARGETS, AIM_WEIGHT, DIRECTION_WEIGHT = 0, 1, 2, 3, 9, 10  # table rows


@njit(cache=True, nogil=True, inline="always")
def _unit_interval(x: float) -> float:
    """`bind._unit_interval`: x clipped to [0, 1], NaN stays NaN, -0.0 becomes 0.0."""
    if x < 0.0:
        return 0.0
    if x > 1.0:
        return 1.0
    return x + 0.0


@njit(cache=True, nogil=True)
def control_plan(
    fur_row: np.ndarray,
    position: np.ndarray,
    rest_position: np.ndarray,
    lift: np.ndarray,
    drive_lift: np.ndarray,
    aim: np.ndarray,
    direction: np.ndarray,
    random: np.ndarray,
    drive_random: np.ndarray,
    dynamic: np.ndarray,
    enabled: np.ndarray,
    twist_max: np.ndarray,
    reach: np.ndarray,
    out_lift: np.ndarray,
    out_aim: np.ndarray,
    out_direction: np.ndarray,
    out_twist: np.ndarray,
    out_position: np.ndarray,
    out_offset: np.ndarray,
    out_dynamic: np.ndarray,
    table: np.ndarray,
) -> tuple[bool, bool, bool, bool]:
    """Every control's effective values (float32; `position` and `offset` as (3, n)),
    its `dynamic` and the rig's table; (lifting, aiming, directing, twisting): whether
    any control's value of that behaviour is not zero."""
    one, zero = F32(1.0), F32(0.0)
    lifting = aiming = directing = twisting = False
    for i in range(len(fur_row)):
        f = fur_row[i]
        lf = F32(_unit_interval(lift[i] + drive_lift[i]) * enabled[f, LIFT])
        am = F32(_unit_interval(aim[i]) * enabled[f, AIM])
        dr = F32(_unit_interval(direction[i]) * enabled[f, DIRECTION])
        rn = _unit_interval(random[i] + drive_random[i]) * enabled[f, RANDOM]
        tw = F32(rn * twist_max[f])
        out_lift[i], out_aim[i], out_direction[i], out_twist[i] = lf, am, dr, tw
        out_dynamic[i] = F32(_unit_interval(dynamic[i]) * enabled[f, DYNAMIC])
        table[UNLIFT, i] = one - lf
        keep = one - am - dr
        table[KEEP, i] = keep if (keep >= zero or keep != keep) else zero  # np.maximum
        table[TWIST, i] = tw
        for k in range(3):
            p = F32(position[i, k])
            o = F32((position[i, k] - rest_position[i, k]) / reach[f])
            out_position[k, i], out_offset[k, i] = p, o
            table[TARGETS + 2 * k, i] = p
            table[TARGETS + 2 * k + 1, i] = o
        table[AIM_WEIGHT, i] = am
        table[DIRECTION_WEIGHT, i] = dr
        lifting |= lf != 0.0
        aiming |= am != 0.0
        directing |= dr != 0.0
        twisting |= tw != 0.0
    return lifting, aiming, directing, twisting
