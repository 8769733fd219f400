"""The numba kernels of tentacle selection (`locomotion/systems/tentacle_selection.py`):
on the plane, each live tentacle's vectors mantle -> goal (turned by the avoidance
term) and mantle -> base, and the thesis's push/pull test on them, in one pass where
the numpy path takes some twenty whole-array operations; the strokes that stop
(`aborts`) and the creatures that start one (`starts`), another twenty.

Optional, as the other kernels are (`ecs_tentacles.numeric.optional_kernels`): the
system uses it only when numba is installed and falls back to numpy otherwise. Both
compute the same numbers bit for bit: the same operations in the same order, no fused
multiply-adds (numba contracts only with `fastmath`).
tests/locomotion/systems/test_tentacle_selection.py compares the two.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def flat_vectors(
    pos: np.ndarray,
    mantle_row: np.ndarray,
    steer: np.ndarray,
    avoidance: np.ndarray,
    base_row: np.ndarray,
    creature_row: np.ndarray,
    live: np.ndarray,
    tolerance: float,
    to_goal: np.ndarray,
    to_base: np.ndarray,
    pull: np.ndarray,
    cos: np.ndarray,
) -> None:
    """At tentacle rows `live`: `to_goal` (the steer point from the mantle, turned by
    the avoidance term as `avoidance.bent` turns it), `to_base` (the tentacle's base
    from the mantle), `cos` of their angle and `pull` (cos >= -tolerance)."""
    for k in range(len(live)):
        row = live[k]
        creature = creature_row[row]
        mantle = mantle_row[creature]
        mx, my = pos[mantle, 0], pos[mantle, 1]
        gx, gy = steer[creature, 0] - mx, steer[creature, 1] - my
        tx, ty = avoidance[creature, 0], avoidance[creature, 1]
        if tx != 0.0 or ty != 0.0:
            length = math.hypot(gx, gy)
            gx, gy = gx + length * tx, gy + length * ty
        base = base_row[row]
        bx, by = pos[base, 0] - mx, pos[base, 1] - my
        to_goal[row, 0], to_goal[row, 1] = gx, gy
        to_base[row, 0], to_base[row, 1] = bx, by
        dot = gx * bx + gy * by
        lengths = math.hypot(gx, gy) * math.hypot(bx, by)
        c = dot / max(lengths, 1e-12)
        cos[row] = c
        pull[row] = c >= -tolerance


@njit(cache=True, nogil=True)
def aborts(
    creature: np.ndarray,
    has_goal: np.ndarray,
    driving: np.ndarray,
    gait: np.ndarray,
    coordinated: int,
    mode: np.ndarray,
    pull: int,
    cos: np.ndarray,
    margin: float,
    replayed: np.ndarray,
) -> np.ndarray:
    """Tentacle rows whose stroke stops: driving, not replayed, and their creature has no
    goal or (a coordinated gait) the goal is more than `margin` on the wrong side."""
    out = np.empty(len(creature), dtype=np.int64)
    found = 0
    for k in range(len(creature)):
        c = creature[k]
        if not driving[k] or replayed[c]:
            continue
        wrong = gait[c] == coordinated and (
            cos[k] < -margin if mode[k] == pull else cos[k] > margin
        )
        if not has_goal[c] or wrong:
            out[found] = k
            found += 1
    return out[:found]


@njit(cache=True, nogil=True)
def starts(
    creature: np.ndarray,
    driving: np.ndarray,
    has_goal: np.ndarray,
    drivers: np.ndarray,
    replayed: np.ndarray,
    gait: np.ndarray,
    cyclic: int,
    speed: np.ndarray,
    last_start: np.ndarray,
    now: float,
    stroke_seconds: float,
) -> tuple[np.ndarray, np.ndarray]:
    """(cyclic, ready): creatures with a goal, not replayed and fewer tentacles driving
    than their gait's drivers; of a cyclic gait with none driving, and of another gait
    whose last start is a stagger (`stroke_seconds / (speed x drivers)`) ago."""
    count = len(has_goal)
    driven = np.zeros(count)
    for k in range(len(creature)):
        if driving[k]:
            driven[creature[k]] += 1.0
    first = np.empty(count, dtype=np.int64)
    ready = np.empty(count, dtype=np.int64)
    nf = nr = 0
    for c in range(count):
        if not (has_goal[c] and driven[c] < drivers[c] and not replayed[c]):
            continue
        if gait[c] == cyclic:
            if driven[c] == 0.0:
                first[nf] = c
                nf += 1
        elif now - last_start[c] >= stroke_seconds / (speed[c] * drivers[c]):
            ready[nr] = c
            nr += 1
    return first[:nf], ready[:nr]
