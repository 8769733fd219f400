"""The REDUCED tier's step of some rows of a batch (`Batch.step_rows`, tier REDUCED).

Reads the batch's full states (`Batch.state`: the frame's inputs, and whether someone
else wrote a row since its last step), its reduced states (`rstate`, `rsource`, a row's
at `rslot`), the overlay (servo gains, torque limits, sucker anchors, proxy sizes) and
the forces scripts apply; writes the reduced states stepped, the full states showing them, the
full model's body poses (`xpos`, `xquat`), the warnings raised, the deepest contacts,
MuJoCo's fatal errors and each row's step cost.

A share's rows go through three parts:
1. for all rows at once (numba kernels, the interpreter's lock released): the frame's
   inputs pulled into the reduced states (fitted again where the full state was
   written from outside), every row's reduced servos;
2. row by row on the thread's scratch: the overlay into the reduced model (what it
   looks up found once for the share, `ReducedModel.overlay_writer`), MuJoCo's
   step (`Batch.advance`: `mj_setState`, `mj_step`, `mj_getState`, the warnings and
   the deepest contact); the bare frames of `physics.bare` do this part alone;
3. for all rows at once: the stepped rows shown as full states and their body poses
   by forward kinematics (`physics.poses`: one numba call, MuJoCo's arithmetic),
   where MuJoCo's `mj_kinematics` ran row by row on the full model before.

Each row's numbers are those it would get alone (the kernels work row by row), so the
result does not depend on the number of threads or on how rows are shared.
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING, Protocol

import numpy as np

from ecs_tentacles.physics.state_layout import Rows, S
from ecs_tentacles.physics.tiers import FULL, REDUCED

if TYPE_CHECKING:
    from ecs_tentacles.physics.poses import PoseMap
    from ecs_tentacles.physics.reduced import ReducedModel
    from ecs_tentacles.physics.scratch import Scratch


class ReducedRows(Rows, Protocol):
    """What the reduced step reads and writes of a batch (`physics.batch.Batch`)."""

    reduced: ReducedModel | None
    pose_map: PoseMap | None
    state: np.ndarray
    rstate: np.ndarray
    rsource: np.ndarray
    rslot: np.ndarray
    xpos: np.ndarray
    xquat: np.ndarray
    applied: dict[int, np.ndarray]
    slices: dict[int, slice]

    def scratch_for(self, thread: int, tier: int = FULL) -> Scratch: ...

    def advance(
        self,
        scratch: Scratch,
        row: int,
        vector: np.ndarray,
        forces: np.ndarray | None,
        substeps: int,
    ) -> bool: ...


def step_reduced(
    batch: ReducedRows, rows: np.ndarray, substeps: int, thread: int
) -> tuple[np.ndarray, float]:
    """Step batch rows `rows` by `substeps` steps of its reduced model on scratch
    `thread`; returns each row's own seconds and the seconds of the parts done for all
    rows at once, per row (for `Batch.step_cost`)."""
    reduced, pose_map = batch.reduced, batch.pose_map
    assert reduced is not None and pose_map is not None  # `prepare(REDUCED)` ran first
    scratch = batch.scratch_for(thread, REDUCED)
    state, rstate, rsource = batch.state, batch.rstate, batch.rsource
    slots = batch.rslot[rows]  # each row's reduced state (`Batch.hold_reduced`: made in `plan`)
    clock = time.perf_counter
    began = clock()
    for at in reduced.pull_into(rows, slots, state, rstate, rsource).tolist():
        reduced.fit_state(state[rows[at]], rstate[slots[at]])
    servos = reduced.servos(batch.kp, batch.kv, batch.torque, rows)
    overlay = reduced.overlay_writer(batch, scratch.model, servos)
    stepped: list[bool] = []
    took: list[float] = []
    shared = clock() - began
    applied, advance = batch.applied, batch.advance
    scratch.warnings[:] = 0  # `advance` clears them after a row that raised one
    for at, (row, slot) in enumerate(zip(rows.tolist(), slots.tolist(), strict=True)):
        began = clock()
        split = overlay(row, at)
        pushed = applied.get(row)
        forces = None if pushed is None else reduced.body_group @ pushed
        stepped.append(advance(scratch, row, rstate[slot], forces, substeps * split))
        took.append(clock() - began)
    began = clock()
    ok = np.array(stepped, dtype=bool)
    done = rows[ok]
    if len(done):
        reduced.show_rows(done, slots[ok], rstate, state, rsource)
        full = batch.scratch_for(thread, FULL)
        pose_map.show(done, state, batch.slices[int(S.mjSTATE_QPOS)], batch.xpos, batch.xquat,
                      full.model, full.data)  # fmt: skip
    shared += clock() - began
    return np.array(took), shared / len(rows) if len(rows) else 0.0
