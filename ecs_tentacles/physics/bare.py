"""MuJoCo alone on the framework's own inputs: what a frame's stepping costs without
the framework (benchmarks, `ecs_tentacles.cli.measure`).

`FrameCapture(world.physics)` calls `capture(physics)` just before each frame's step (until
`close()`), which copies what that step will read of every row it steps: the state (a
REDUCED row's reduced state, fitted or with the frame's inputs pulled in as its step
will), the overlay (servo gains, torque limits, sucker anchors, proxy sizes) and the
forces scripts apply. `step_captured` (`PhysicsBackend.step_bare`) later steps those
copies with MuJoCo alone on the backend's threads (overlay into the thread's scratch
model, `mj_setState`, `mj_step`, `mj_getState`; into `after` when the frame was
captured with `keep`, else into a scratch vector), shares handed out as the
framework's are. A captured frame can be stepped again and again: its inputs are never
written.

So a bare frame does the framework frame's very work: the same states, contacts and
solver iterations, and the same results (a test). Only creatures near another differ:
the framework steps them in parts with their contact proxies moved between, a bare
frame steps them whole. Stepping copies of the state on by themselves with the last
frame's controls, as the bare frames did before, let the creatures come to rest:
MuJoCo then needed 2.6 solver iterations a step against the framework's 5.1 (16
octopuses), and the framework looked 19 % dearer than MuJoCo where it is not.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Protocol

import mujoco
import numpy as np

from ecs_tentacles.physics.batch import Batch
from ecs_tentacles.physics.state_layout import STATE, write_overlay
from ecs_tentacles.physics.tiers import FULL, REDUCED

if TYPE_CHECKING:
    from ecs_tentacles.physics.stepping import Work


class Stepped(Protocol):
    """What `capture` reads of the physics (`PhysicsBackend`)."""

    batches: list[Batch]
    threads: int

    @property
    def active(self) -> np.ndarray: ...

    @property
    def tier(self) -> np.ndarray: ...


class Steps(Stepped, Protocol):
    """The physics a `FrameCapture` follows: what `capture` reads, and its step."""

    def step(
        self,
        substeps: int,
        before_substep: Callable[[int], None] | None = None,
        rounds: int = 1,
        between: Callable[[Callable[[np.ndarray], None]], None] | None = None,
    ) -> None: ...


@dataclass
class CapturedRows:
    """Some rows of one batch at one tier as its step will read them (the `Rows` the
    overlay writers read: per captured row, in `rows` order)."""

    rows: np.ndarray  # the batch's rows, ascending
    states: np.ndarray  # the state each step starts from (the tier's model's layout)
    kp: np.ndarray
    kv: np.ndarray
    torque: np.ndarray
    anchor: np.ndarray
    near: np.ndarray
    proxy_size: np.ndarray
    proxy_cylinder: np.ndarray  # the batch's
    proxy_geoms: np.ndarray  # the batch's
    equality_ids: np.ndarray  # the batch's
    forces: dict[int, np.ndarray] = field(default_factory=dict)  # by position: xfrc_applied
    after: np.ndarray | None = None  # the steps' results (captured with `keep`)


@dataclass(frozen=True)
class BareFrame:
    """One frame's stepping inputs: who steps at which tier, and each batch's rows."""

    active: np.ndarray  # per creature (backend order)
    tier: np.ndarray
    rows: list[dict[int, CapturedRows]]  # per batch, per stepped tier


def capture(backend: Stepped, keep: bool = False) -> BareFrame:
    """What `backend.step` would read now, copied (call it just before the step); with
    `keep`, room for the bare steps' results (`CapturedRows.after`)."""
    active, tier = backend.active.copy(), backend.tier.copy()
    per_batch: list[dict[int, CapturedRows]] = []
    for batch in backend.batches:
        captured: dict[int, CapturedRows] = {}
        for level in (FULL, REDUCED):
            rows = np.flatnonzero(active[batch.members] & (tier[batch.members] == level))
            if not len(rows):
                continue
            if level == REDUCED:
                states = _reduced_states(backend, batch.index, rows)
            else:
                states = batch.state[rows].copy()
            at = {int(r): p for p, r in enumerate(rows.tolist())} if batch.applied else {}
            applied = {at[r]: f for r, f in batch.applied.items() if r in at}  # few: scripts
            if level == REDUCED and applied:
                assert batch.reduced is not None
                applied = {p: batch.reduced.body_group @ f for p, f in applied.items()}
            captured[level] = CapturedRows(
                rows, states, batch.kp[rows].copy(), batch.kv[rows].copy(),
                batch.torque[rows].copy(), batch.anchor[rows].copy(), batch.near[rows].copy(),
                batch.proxy_size[rows].copy(), batch.proxy_cylinder, batch.proxy_geoms,
                batch.equality_ids, {p: f.copy() for p, f in applied.items()},
                np.zeros_like(states) if keep else None,
            )  # fmt: skip
        per_batch.append(captured)
    return BareFrame(active, tier, per_batch)


class FrameCapture:
    """Captures each frame's stepping inputs (`capture`) just before `physics` steps it,
    by wrapping its `step` until `close()`; `seconds` is what the capture took (the
    bench takes it out of the framework's time). `keep`: as in `capture`."""

    def __init__(self, physics: Steps, keep: bool = False) -> None:
        self.physics = physics
        self.frames: list[BareFrame] = []
        self.seconds = 0.0
        step = physics.step

        def capturing_step(
            substeps: int,
            before_substep: Callable[[int], None] | None = None,
            rounds: int = 1,
            between: Callable[[Callable[[np.ndarray], None]], None] | None = None,
        ) -> None:
            began = time.perf_counter()
            self.frames.append(capture(physics, keep))
            self.seconds += time.perf_counter() - began
            step(substeps, before_substep, rounds, between)

        physics.step = capturing_step  # type: ignore[method-assign]

    def close(self) -> None:
        """Stop capturing: `physics.step` is its class's again."""
        del self.physics.step


def _reduced_states(backend: Stepped, index: int, rows: np.ndarray) -> np.ndarray:
    """The reduced states REDUCED `rows` of batch `index` will start their step from:
    fitted again where the full state was written from outside, else the frame's
    inputs pulled in (`physics.reduced_step`)."""
    batch = backend.batches[index]
    batch.prepare(REDUCED, backend.threads)
    reduced = batch.reduced
    assert reduced is not None
    out: np.ndarray = batch.rstate[rows].copy()
    for position, row in enumerate(rows.tolist()):
        full = batch.state[row]
        if np.array_equal(full[reduced.watched], batch.rsource[row]):
            reduced.pull_inputs(full, out[position])
        else:
            reduced.fit_state(full, out[position])
    return out


def step_captured(work: Work, frame: BareFrame, substeps: dict[int, int], thread: int) -> None:
    """Step shares of `frame`'s rows taken from `work` with MuJoCo alone on scratch
    `thread`, each by its tier's `substeps`, results into `after` if kept (runs on each
    thread of a dispatch)."""
    while (segment := work.take()) is not None:
        batch = segment.batch
        captured = frame.rows[batch.index][segment.tier]
        scratch = batch.scratch_for(thread, segment.tier)
        m, d, n = scratch.model, scratch.data, substeps[segment.tier]
        reduced = batch.reduced if segment.tier == REDUCED else None
        kept = captured.after
        out = kept if kept is not None else np.empty((1, captured.states.shape[1]))
        if scratch.forced:  # the framework's last step there applied forces
            d.xfrc_applied[:] = 0.0
            scratch.forced = False
        positions = np.searchsorted(captured.rows, segment.rows)
        overlay = None  # as `physics.reduced_step` forms the servos: for all at once
        if reduced is not None:
            servos = reduced.servos(
                captured.kp[positions], captured.kv[positions], captured.torque[positions]
            )
            overlay = reduced.overlay_writer(captured, m, servos)
        for at, position in enumerate(positions.tolist()):
            split = 1
            if overlay is not None:
                split = overlay(position, at)
            else:
                write_overlay(captured, m, position)
            forces = captured.forces.get(position)
            if forces is not None:
                d.xfrc_applied[:] = forces
            mujoco.mj_setState(m, d, captured.states[position], STATE)
            mujoco.mj_step(m, d, nstep=n * split)
            mujoco.mj_getState(m, d, out[position if kept is not None else 0], STATE)
            if forces is not None:
                d.xfrc_applied[:] = 0.0
