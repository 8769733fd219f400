"""The numba kernels of the reduced tier (`physics.reduced`): its maps (the full servo
commands pulled into a reduced state, a reduced state's joints shown on the full
skeleton, each a weighted sum over a group of columns), a share's rows pulled and shown
in place (the maps row by row, no gathered copies: a share of 64 crowd creatures on
rocky ground spent about 120 us a call in numpy's gathers and scatters), its servos'
gains, and a row's servos written into the scratch model before its step.

Optional, as the other kernels are: `ReducedModel` imports this module only when numba
is installed and falls back to numpy otherwise; both give the same numbers bit for bit
(the same products summed in the same order, the same clip; tests/physics/
test_reduced_kernels.py compares them). Both run on the stepping threads, once a
share: numpy's passes there hold the interpreter's lock, which the other thread then
waits for between its steps; the kernels release it.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def group_sums_into(
    values: np.ndarray,
    rows: np.ndarray,
    columns: np.ndarray,
    members: np.ndarray,
    weights: np.ndarray,
    low: np.ndarray,
    high: np.ndarray,
    out: np.ndarray,
    out_rows: np.ndarray,
    out_columns: np.ndarray,
) -> None:
    """For each i, r = rows[i], and each k: the sum over p, in order, of
    values[r, columns[members[k, p]]] x weights[k, p], clipped into [low[k], high[k]]
    when `low` is not empty (NaN stays NaN), into out[out_rows[i], out_columns[k]]."""
    clip = low.shape[0] > 0
    for i in range(rows.shape[0]):
        r = rows[i]
        o = out_rows[i]
        for k in range(members.shape[0]):
            total = values[r, columns[members[k, 0]]] * weights[k, 0]
            for p in range(1, members.shape[1]):
                total += values[r, columns[members[k, p]]] * weights[k, p]
            if clip:
                if total < low[k]:
                    total = low[k]
                if total > high[k]:
                    total = high[k]
            out[o, out_columns[k]] = total


@njit(cache=True, nogil=True)
def pull_into(
    rows: np.ndarray,
    slots: np.ndarray,
    state: np.ndarray,
    source: np.ndarray,
    watched: np.ndarray,
    rstate: np.ndarray,
    inputs: np.ndarray,
    commands: np.ndarray,
    members: np.ndarray,
    weights: np.ndarray,
    servos: np.ndarray,
    changed: np.ndarray,
) -> None:
    """`ReducedModel.pull_into` in place: for each of `rows` (its reduced rows at
    `slots`) whose full state's entries watched[0]:watched[1] equal its `source` row (as
    its last step left them), the frame's inputs copied (`inputs`: full columns, reduced
    columns) and its servo commands (full columns `commands`) summed into its `rstate`
    row (columns `servos`); the others marked in `changed` (a NaN there counts as
    changed, as numpy's ==)."""
    start, stop = watched[0], watched[1]
    pulled = np.empty(rows.shape[0], dtype=np.int64)
    into = np.empty(rows.shape[0], dtype=np.int64)
    count = 0
    for i in range(rows.shape[0]):
        row = rows[i]
        slot = slots[i]
        same = True
        for c in range(start, stop):
            if state[row, c] != source[slot, c - start]:
                same = False
                break
        if not same:
            changed[i] = True
            continue
        for c in range(inputs.shape[1]):
            rstate[slot, inputs[1, c]] = state[row, inputs[0, c]]
        pulled[count] = row
        into[count] = slot
        count += 1
    none = np.zeros(0)
    group_sums_into(state, pulled[:count], commands, members, weights, none, none, rstate,
                    into[:count], servos)  # fmt: skip


@njit(cache=True, nogil=True)
def show_rows(
    rows: np.ndarray,
    slots: np.ndarray,
    rstate: np.ndarray,
    state: np.ndarray,
    shown: np.ndarray,
    angles: np.ndarray,
    full_angles: np.ndarray,
    speeds: np.ndarray,
    full_speeds: np.ndarray,
    members: np.ndarray,
    weights: np.ndarray,
    low: np.ndarray,
    high: np.ndarray,
    warm: np.ndarray,
    watched: np.ndarray,
    source: np.ndarray,
) -> None:
    """`ReducedModel.show_rows` in place: each of `rows`' reduced state (its row at
    `slots` of `rstate`) shown as its full state (`shown` (reduced columns, full
    columns) copied; the reduced columns `angles` summed and clipped into [low, high]
    into the full columns `full_angles`, `speeds` into `full_speeds`; the warm start
    warm[0]:warm[1] cleared), and
    the full state's watched[0]:watched[1] kept in its `source` row (at `slots`)."""
    none = np.zeros(0)
    group_sums_into(rstate, slots, angles, members, weights, low, high, state, rows, full_angles)
    group_sums_into(rstate, slots, speeds, members, weights, none, none, state, rows, full_speeds)
    for i in range(rows.shape[0]):
        row = rows[i]
        slot = slots[i]
        for c in range(shown.shape[1]):
            state[row, shown[1, c]] = rstate[slot, shown[0, c]]
        for c in range(warm[0], warm[1]):
            state[row, c] = 0.0
        for c in range(watched[0], watched[1]):
            source[slot, c - watched[0]] = state[row, c]


@njit(cache=True, nogil=True, inline="always")
def _softest(gain: float) -> float:
    """1 / max(gain, 1e-12), NaN kept (as numpy's `1.0 / np.maximum(gain, 1e-12)`)."""
    return 1.0 / (gain if gain >= 1e-12 or math.isnan(gain) else 1e-12)


@njit(cache=True, nogil=True, error_model="numpy")
def servos(
    rows: np.ndarray,
    kp: np.ndarray,
    kv: np.ndarray,
    full_u: np.ndarray,
    members: np.ndarray,
    weights: np.ndarray,
    stiff_per_kp: np.ndarray,
    critical_per_sqrt_kp: np.ndarray,
    constants: np.ndarray,
    gains: np.ndarray,
    damping: np.ndarray,
    split: np.ndarray,
) -> None:
    """`ReducedModel.servos`' numbers for rows `rows` of `kp` / `kv` (full actuators),
    into `gains`, `damping` (len(rows), reduced servos) and `split`; `constants` are the
    stiffness gain, damping gain, damping cap, stiff step and most splits. Division by
    zero gives infinities, as numpy's (error_model="numpy")."""
    stiffness_gain, damping_gain, cap = constants[0], constants[1], constants[2]
    stiff_step, most = constants[3], constants[4]
    width = members.shape[1]
    for i in range(rows.shape[0]):
        r = rows[i]
        stiffest = -np.inf
        for k in range(members.shape[0]):
            compliance = _softest(kp[r, full_u[members[k, 0]]]) * weights[k, 0]
            matched = _softest(kv[r, full_u[members[k, 0]]]) * weights[k, 0]
            for p in range(1, width):
                compliance += _softest(kp[r, full_u[members[k, p]]]) * weights[k, p]
                matched += _softest(kv[r, full_u[members[k, p]]]) * weights[k, p]
            gain = stiffness_gain / compliance
            gains[i, k] = gain
            stiff = gain * stiff_per_kp[k]
            if not math.isnan(stiffest) and (stiff > stiffest or math.isnan(stiff)):
                stiffest = stiff  # np.max: NaN wins
            matched_kv = 1.0 / matched
            critical = math.sqrt(gain) * critical_per_sqrt_kp[k]
            soft = damping_gain * matched_kv
            capped = stiffness_gain * matched_kv + cap * critical
            damping[i, k] = soft if soft <= capped or math.isnan(soft) else capped
        split[i] = 1
        if stiffest > stiff_step and stiffest < np.inf:
            split[i] = int(min(math.ceil(math.sqrt(stiffest / stiff_step)), most))


@njit(cache=True, nogil=True)
def servo_overlay(
    gainprm: np.ndarray,
    biasprm: np.ndarray,
    forcerange: np.ndarray,
    actuators: np.ndarray,
    kp: np.ndarray,
    kv: np.ndarray,
    torque: np.ndarray,
    eq_data: np.ndarray,
    equalities: np.ndarray,
    anchor: np.ndarray,
) -> None:
    """One row's servos and sucker anchors into a scratch model's arrays (MjModel's
    `actuator_gainprm`, `actuator_biasprm`, `actuator_forcerange`, `eq_data`): actuator
    `actuators[i]` gets gain kp[i], damping kv[i] and torque limit torque[i], equality
    `equalities[e]` the anchor `anchor[e]`; what `ReducedModel.write_overlay`'s numpy
    assignments write, in one call (a fifth of their time, once a row a frame)."""
    for i in range(len(actuators)):
        a = actuators[i]
        gainprm[a, 0] = kp[i]
        biasprm[a, 1] = -kp[i]
        biasprm[a, 2] = -kv[i]
        forcerange[a, 0] = -torque[i]
        forcerange[a, 1] = torque[i]
    for e in range(len(equalities)):
        for k in range(3):
            eq_data[equalities[e], 3 + k] = anchor[e, k]


@njit(cache=True, nogil=True)
def running_costs(
    cost: np.ndarray,
    rows: np.ndarray,
    column: int,
    took: np.ndarray,
    shared: float,
    substeps: int,
) -> None:
    """Row rows[i]'s step took took[i] + `shared` seconds for `substeps` steps: into
    cost[rows[i], column] as `Batch`'s running mean (the first as it is, then 3/4 of
    the last plus 1/4 of the new)."""
    for i in range(rows.shape[0]):
        seconds = (took[i] + shared) / substeps
        last = cost[rows[i], column]
        cost[rows[i], column] = seconds if last == 0.0 else 0.75 * last + 0.25 * seconds
