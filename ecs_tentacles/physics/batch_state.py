"""One batch's part of a physics snapshot (`PhysicsBackend.state()` / `set_state()`).

`saved(batch)` copies what decides how a batch steps on: its state rows, its body poses
(the replayed rows' as shown), its reduced rows, which rows are not placed yet, and the
forces scripts apply; `problem(batch, saved)` says why it would not fit the batch (one
line) or None; `restore(batch, saved)` puts it back and drops the warnings and errors
counted since (neither is state).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.physics.placing import PlacingState

if TYPE_CHECKING:
    from ecs_tentacles.physics.batch import Batch


@dataclass(frozen=True)
class BatchState:
    """A copy of one batch's state (see the module's docstring); opaque to callers."""

    states: np.ndarray  # its state rows
    poses: tuple[np.ndarray, np.ndarray]  # xpos, xquat after the last step
    reduced: tuple[np.ndarray, np.ndarray, np.ndarray]  # rslot, rstate, rsource
    placing: PlacingState  # the rows not placed yet (`physics.placing`)
    applied: dict[int, np.ndarray]  # forces scripts apply


def saved(batch: Batch) -> BatchState:
    return BatchState(
        states=batch.state.copy(),
        poses=batch.all_poses(),  # the replayed ones as shown
        reduced=(batch.rslot.copy(), batch.rstate.copy(), batch.rsource.copy()),
        placing=batch.placing_state(),
        applied={r: f.copy() for r, f in batch.applied.items()},
    )


def problem(batch: Batch, state: BatchState) -> str | None:
    if state.states.shape != batch.state.shape or state.poses[0].shape != batch.xpos.shape:
        return f"batch {batch.index}: state {state.states.shape}, here {batch.state.shape}"
    return None


def restore(batch: Batch, state: BatchState) -> None:
    xpos, xquat = state.poses
    batch.set_rows(state.states, xpos, xquat, state.placing)
    batch.show(None, None)  # every row's poses as saved, replayed ones too
    rslot, rstate, rsource = state.reduced
    if rstate.shape[1] == batch.rstate.shape[1]:
        batch.rslot[:], batch.rstate, batch.rsource = rslot, rstate.copy(), rsource.copy()
    else:  # compiled since: no row was REDUCED then; each fits on its first step
        batch.release_reduced(np.arange(len(batch)))
    batch.applied = {r: f.copy() for r, f in state.applied.items()}
    batch.warnings[:] = 0
    batch.errors.clear()
