"""The numba kernels of the physics' own per-frame bookkeeping: the servo commands and
the sucker switches into the batch rows (`PhysicsBackend.write_controls`,
`write_suckers`), the fastest body of every creature and the rows' faults
(`HealthCheck.check`), and the body poses into the Transform store (`Batch.sync`).

Optional, as the other kernels are: their users import this module only when numba is
installed and fall back to numpy otherwise; both compute the same numbers bit for bit
(the same operations in the same order; tests/physics/test_frame_kernels.py compares
them). Each replaces half a dozen numpy passes over small arrays; right after MuJoCo's
step, with the caches cold, those cost 40-50 us a frame at 16 creatures, time the
stepping threads wait through.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def servo_commands(
    target: np.ndarray,
    target_index: np.ndarray,
    strength: np.ndarray,
    gain: np.ndarray,
    damping: np.ndarray,
    max_torque: np.ndarray,
    motor_rows: np.ndarray,
    soften: np.ndarray,
    rows: np.ndarray,
    ctrl: np.ndarray,
    kp: np.ndarray,
    kv: np.ndarray,
    torque: np.ndarray,
) -> None:
    """For each batch row of `rows`: its actuators' targets (`target`, flat, at
    `target_index` clipped into range) into `ctrl`, kp = strength x gain x soften,
    kv = damping x gain and the torque limits, from the motor rows `motor_rows`."""
    last = len(target) - 1
    for i in range(len(rows)):
        r = rows[i]
        s = soften[r]
        for j in range(target_index.shape[1]):
            t = min(max(target_index[r, j], 0), last)
            ctrl[r, j] = target[t]
            m = motor_rows[r, j]
            g = gain[m]
            kp[r, j] = strength[m] * g * s
            kv[r, j] = damping[m] * g
            torque[r, j] = max_torque[m]


@njit(cache=True, nogil=True)
def fastest_moves(
    pos: np.ndarray,
    previous: np.ndarray,
    rows: np.ndarray,
    start: np.ndarray,
    count: np.ndarray,
    who: np.ndarray,
    out: np.ndarray,
) -> None:
    """For each creature c of `who`, the largest distance one of its bodies (store rows
    `rows[start[c]:start[c] + count[c]]`) moved from `previous` to `pos`, into `out[c]`
    (NaN when a position is not finite)."""
    for k in range(len(who)):
        c = who[k]
        best = -np.inf
        for i in range(start[c], start[c] + count[c]):
            row = rows[i]
            dx = pos[row, 0] - previous[row, 0]
            dy = pos[row, 1] - previous[row, 1]
            dz = pos[row, 2] - previous[row, 2]
            step = dx * dx + dy * dy + dz * dz
            if step > best or step != step:  # NaN wins, as in np.maximum
                best = step
                if step != step:
                    break
        out[c] = math.sqrt(best) if count[c] else 0.0


@njit(cache=True, nogil=True)
def copy_bodies(
    pos: np.ndarray,
    previous: np.ndarray,
    rows: np.ndarray,
    start: np.ndarray,
    count: np.ndarray,
    who: np.ndarray,
) -> None:
    """`HealthCheck._remember`: for each creature c of `who`, its bodies' positions (store
    rows `rows[start[c]:start[c] + count[c]]`) from `pos` into `previous`."""
    for k in range(len(who)):
        c = who[k]
        for i in range(start[c], start[c] + count[c]):
            row = rows[i]
            for j in range(3):
                previous[row, j] = pos[row, j]


@njit(cache=True, nogil=True)
def row_faults(
    members: np.ndarray,
    active: np.ndarray,
    warnings: np.ndarray,
    qvel: np.ndarray,
    deepest: np.ndarray,
    max_penetration: float,
    bad: np.ndarray,
) -> None:
    """`bad[members[r]] = True` for each row r of a batch whose creature is `active` and
    whose step raised a warning, left a velocity that is not finite, or a contact deeper
    than `max_penetration`."""
    for r in range(len(members)):
        c = members[r]
        if not active[c]:
            continue
        fault = deepest[r] < -max_penetration
        for k in range(warnings.shape[1]):
            if warnings[r, k] != 0:
                fault = True
        for k in range(qvel.shape[1]):
            if not math.isfinite(qvel[r, k]):
                fault = True
                break
        if fault:
            bad[c] = True


@njit(cache=True, nogil=True)
def sucker_switches(
    live: np.ndarray,
    sucker_rows: np.ndarray,
    anchors: np.ndarray,
    attached: np.ndarray,
    batch_anchor: np.ndarray,
    state: np.ndarray,
    first: int,
) -> None:
    """`PhysicsBackend.write_suckers` for one batch: each of batch rows `live` gets its
    suckers' (store rows `sucker_rows[row]`) world anchors in `batch_anchor[row]` and
    their switches (1.0 attached, else 0.0) in state[row, first:]."""
    for row in live:
        for e in range(sucker_rows.shape[1]):
            sucker = sucker_rows[row, e]
            for k in range(3):
                batch_anchor[row, e, k] = anchors[sucker, k]
            state[row, first + e] = 1.0 if attached[sucker] else 0.0


@njit(cache=True, nogil=True)
def scatter_poses(
    body_rows: np.ndarray, xpos: np.ndarray, xquat: np.ndarray, pos: np.ndarray, quat: np.ndarray
) -> None:
    """`Batch.sync`: every row's body poses (xpos, xquat: rows, bodies, 3 / 4) into the
    Transform store's rows `body_rows` (rows, bodies) of `pos` and `quat`."""
    for r in range(body_rows.shape[0]):
        for b in range(body_rows.shape[1]):
            at = body_rows[r, b]
            for k in range(3):
                pos[at, k] = xpos[r, b, k]
            for k in range(4):
                quat[at, k] = xquat[r, b, k]


@njit(cache=True, nogil=True)
def sleep_rows(
    members: np.ndarray,
    commanded: np.ndarray,
    proxies_used: np.ndarray,
    wants: np.ndarray,
    creature_row: np.ndarray,
    attached: np.ndarray,
    sucker_rows: np.ndarray,
    ctrl: np.ndarray,
    kp: np.ndarray,
    qvel: np.ndarray,
    previous: np.ndarray,
    limits: np.ndarray,
    known: np.ndarray,
    still: np.ndarray,
    sleeping: np.ndarray,
) -> None:
    """`Sleep.update` for one batch's rows (`members`: their creatures): a commanded
    creature is calm when it has no proxies, its last commands are known, no plugin
    `wants` it to move (empty: none does), none of its suckers is attached and its
    commands (ctrl, kp) moved less than limits[0] since `previous` (NaN: moved); its
    commands are kept; a restless one is awake with its stillness count at 0, a calm
    one awake counts a still frame when its fastest speed is below limits[1] (NaN: not
    moving, as numpy's max and >=), else restarts, and sleeps at limits[2] frames."""
    change, speed, settle = limits[0], limits[1], limits[2]
    nu = ctrl.shape[1]
    for r in range(members.shape[0]):
        i = members[r]
        if not commanded[i]:
            continue
        calm = proxies_used[i] == 0 and known[i]
        if calm and wants.shape[0] and wants[creature_row[i]]:
            calm = False
        if calm:
            for e in range(sucker_rows.shape[1]):
                if attached[sucker_rows[r, e]]:
                    calm = False
                    break
        if calm:
            for j in range(nu):
                if not (abs(ctrl[r, j] - previous[r, j]) < change):
                    calm = False
                    break
                if not (abs(kp[r, j] - previous[r, nu + j]) < change):
                    calm = False
                    break
        for j in range(nu):
            previous[r, j] = ctrl[r, j]
            previous[r, nu + j] = kp[r, j]
        known[i] = True
        if not calm:
            still[i] = 0
            sleeping[i] = False
            continue
        if sleeping[i]:
            continue
        fastest = 0.0
        for j in range(qvel.shape[1]):
            v = abs(qvel[r, j])
            if v != v:
                fastest = v
                break
            if v > fastest:
                fastest = v
        still[i] = 0 if fastest >= speed else still[i] + 1
        sleeping[i] = still[i] >= settle
