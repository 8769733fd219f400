"""The numba kernel of the action queue (`locomotion/systems/action_queue.py`): every
tentacle's timer advanced and the tentacles whose action ends this frame found, in one
pass over the tentacles where the numpy path makes six whole-array temporaries (at
10,000 creatures, 80,000 tentacles, most of them of replayed creatures).

Optional, as the other kernels are (`ecs_tentacles.numeric.optional_kernels`): the
system uses it only when numba is installed and falls back to numpy otherwise. Both
compute the same numbers bit for bit (the same operations in the same order, no fused
multiply-adds); tests/locomotion/systems/test_action_queue.py compares the two.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def due(
    timer: np.ndarray,
    duration: np.ndarray,
    action: np.ndarray,
    interrupted: np.ndarray,
    creature_row: np.ndarray,
    replayed: np.ndarray,
    attached: np.ndarray,
    tip_sucker: np.ndarray,
    dt: float,
    epsilon: float,
    attach: int,
    patience: float,
) -> np.ndarray:
    """Advance every `timer` by `dt`; return the rows (ascending) whose action is done:
    its timer reached its duration (an attach also waits for its tip's sucker, up to
    `patience` times its duration) or it was interrupted, unless its creature is
    `replayed`; their `interrupted` flags are cleared."""
    out = np.empty(len(timer), dtype=np.int64)
    found = 0
    for i in range(len(timer)):
        timer[i] += dt
        done = timer[i] >= duration[i] - epsilon
        if action[i] == attach:
            done = done and (
                attached[tip_sucker[i]] or timer[i] >= patience * duration[i] - epsilon
            )
        if interrupted[i]:
            done = True
        if done and replayed[creature_row[i]]:
            done = False
        if done:
            interrupted[i] = False
            out[found] = i
            found += 1
    return out[:found]
