"""Every creature of one morphology: one shared compiled model, state in arrays.

A `Batch` holds the compiled model of a morphology (`model_layout(...).key`) once, and
each of its creatures as one row of contiguous arrays: the MuJoCo state (`state`:
time, qpos, qvel, warm start, ctrl, sucker switches, proxy poses; `STATE`), what
differs per creature in the model (servo gains and torque limits, sucker anchors,
proxy sizes: the *overlay*), the body poses the last step produced (`xpos`, `xquat`;
a replayed row's poses are written into the Transform store instead: `show`, `poses`)
and what the health check needs from it (warnings raised, deepest contact, fatal
errors). Nothing per creature is a MuJoCo object. A row is placed at the build, or, in a
crowd replayed from its first frame, when first needed (`physics.placing`): the state
and pose tables are resident only for the rows written.

A batch is stepped by `step_rows`: each stepping thread owns one scratch copy of the
model and one MjData (`Scratch`), and steps its share of the rows one after another:
overlay into the scratch model, `mj_setState`, `mj_step`, `mj_getState`, poses out. A
creature's step therefore reads only its own row, so results never depend on the
number of threads or on which thread stepped which creature, and a creature steps
exactly as it would alone in its own model and data. REDUCED rows are stepped with the
reduced model and shown as the full creature (`physics.reduced_step`).
"""

from __future__ import annotations

import copy
import time
from collections.abc import Callable
from typing import TYPE_CHECKING

import mujoco
import numpy as np

from ecs_tentacles.numeric.rows import run_slice, without_row
from ecs_tentacles.numeric.untouched import untouched_zeros
from ecs_tentacles.physics.batch_poses import BatchPoses
from ecs_tentacles.physics.model import PROXY_CAPSULES, PROXY_CYLINDERS, PROXY_SLOTS, ModelLayout
from ecs_tentacles.physics.placing import Placing
from ecs_tentacles.physics.poses import PoseMap
from ecs_tentacles.physics.reduced import KERNELS as REDUCED_KERNELS
from ecs_tentacles.physics.reduced_step import step_reduced
from ecs_tentacles.physics.scratch import Scratch
from ecs_tentacles.physics.state_layout import STATE, S, state_slices, write_overlay
from ecs_tentacles.physics.tiers import FULL, REDUCED, REDUCED_RATE

if TYPE_CHECKING:
    from ecs_tentacles.physics.reduced import ReducedModel
    from ecs_tentacles.store import TransformStore

WARNING_KINDS = len(mujoco.MjData(mujoco.MjModel.from_xml_string("<mujoco/>")).warning)


def _ids(model: mujoco.MjModel, kind: mujoco.mjtObj, names: list[str]) -> np.ndarray:
    return np.array([mujoco.mj_name2id(model, kind, n) for n in names], dtype=np.int64)


class Batch(BatchPoses, Placing):
    """The creatures of one morphology: a shared model and their rows of state."""

    def __init__(
        self,
        index: int,
        model: mujoco.MjModel,
        layouts: list[ModelLayout],
        reduced: Callable[[], ReducedModel] | None = None,
    ):
        self.index = index
        self.model = model  # shared, never written: scratch copies take the overlay
        self._full_guess = 1e-6 * (model.nv + 1.0)  # `frame_cost` before a row's first step
        self.models = {FULL: model}  # per tier; REDUCED compiled on first use
        self._compile_reduced = reduced
        self.reduced: ReducedModel | None = None  # the REDUCED tier's model (`physics.reduced`)
        self.pose_map: PoseMap | None = None  # its show step's kinematics (`physics.poses`)
        m, obj = model, mujoco.mjtObj
        n = len(layouts)
        first = layouts[0]
        self.body_ids = _ids(m, obj.mjOBJ_BODY, first.bodies)
        # the same rows as a slice when they are one run (a copy without a gather)
        span = run_slice(self.body_ids)
        self.model_bodies: slice | np.ndarray = self.body_ids if span is None else span
        actuators = _ids(m, obj.mjOBJ_ACTUATOR, first.actuators)
        order = np.argsort(actuators)
        self.equality_ids = _ids(m, obj.mjOBJ_EQUALITY, first.equalities)
        proxies = [f"proxy/capsule{i}" for i in range(PROXY_CAPSULES)]
        proxies += [f"proxy/cylinder{i}" for i in range(PROXY_CYLINDERS)]
        self.proxy_geoms = _ids(m, obj.mjOBJ_GEOM, proxies)
        self.proxy_mocap = m.body_mocapid[_ids(m, obj.mjOBJ_BODY, proxies)]
        self.proxy_cylinder = m.geom_type[self.proxy_geoms] == mujoco.mjtGeom.mjGEOM_CYLINDER
        self.root_qpos = int(m.jnt_qposadr[m.joint("root").id])
        # the morphology (None: retired, `rebuild_models`)
        self.key: tuple[object, ...] | None = first.key
        self._order = order
        # store rows, one row of each per creature
        (self.body_rows, self.actuator_motor_rows, self.actuator_target_index,
         self.sucker_rows) = self._store_rows(layouts)  # fmt: skip
        self.members = np.zeros(n, dtype=np.int64)  # creature index (backend order) per row
        # the state and its parts (resident where written when the build only shows the
        # rows, `physics.placing`)
        self.slices = state_slices(m)
        self.state = np.zeros((n, mujoco.mj_stateSize(m, STATE)))
        self.unplaced: np.ndarray | None = None  # rows not placed yet (`physics.placing`)
        self.placement = np.zeros((0, 7))
        self.placed_in: TransformStore | None = None
        self.when_placed: Callable[[np.ndarray], None] | None = None
        # the overlay: what differs per creature in the model; the servos' written for
        # the rows commanded only (a replayed row's when it is promoted): resident there
        self.kp = untouched_zeros((n, m.nu))
        self.kv = untouched_zeros((n, m.nu))
        self.torque = untouched_zeros((n, m.nu))
        self.anchor = np.zeros((n, len(self.equality_ids), 3))
        self.proxy_size = np.full((n, PROXY_SLOTS, 2), 0.01)
        self.near = np.zeros(n, dtype=bool)  # proxies placed (parked ones need no size)
        self.applied: dict[int, np.ndarray] = {}  # row -> xfrc_applied, while a script pushes
        # what the last step produced
        self.xpos = np.zeros((n, len(self.body_ids), 3))
        self.xquat = np.zeros((n, len(self.body_ids), 4))
        self.warnings = np.zeros((n, WARNING_KINDS), dtype=np.int64)  # raised since checked
        self.deepest = np.full(n, np.inf)  # deepest contact distance (m; < 0 penetrates)
        self.errors: dict[int, str] = {}  # row -> MuJoCo's fatal error in the last step
        # seconds one step of a row took lately, per tier (FULL, REDUCED): how `plan`
        # shares rows between threads (a creature on rocks costs more than one at rest)
        self.step_cost = np.zeros((n, 2))
        # REDUCED rows: their reduced model's state, and the part of the full state the
        # last reduced step wrote (when it differs, someone else wrote it: fit again),
        # a row of each at `rslot` (-1: none) for the rows that step REDUCED only
        # (`hold_reduced`; 10,000 creatures' were 93 MB). No columns until the reduced
        # model is compiled.
        self.rslot = np.full(n, -1, dtype=np.int64)
        self.rstate = np.zeros((0, 0))
        self.rsource = np.zeros((0, 0))
        self.scratch: dict[int, list[Scratch]] = {FULL: []}
        # `body_rows` as one slice of the Transform store when they are consecutive (a
        # uniform crowd): `sync` then copies instead of scattering, 6x faster at 10,000
        self._span: slice | None = None
        self._span_of: np.ndarray | None = None  # the body_rows the span was found for
        # rows (bool per row) whose poses the replay wrote into the Transform store
        # `shown_in` this frame instead of `xpos` / `xquat`, which keep the row's last
        # stepped pose: `sync` copies the others only, `poses(row)` reads them there
        self.shown: np.ndarray | None = None
        self.shown_in: TransformStore | None = None

    # the per-row arrays, in the order `append` and `remove` treat them
    PER_ROW = ("body_rows", "actuator_motor_rows", "actuator_target_index", "sucker_rows",
               "members", "state", "kp", "kv", "torque", "anchor", "proxy_size", "near",
               "xpos", "xquat", "warnings", "deepest", "rslot", "step_cost")  # fmt: skip

    def _store_rows(
        self, layouts: list[ModelLayout]
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Body, actuator motor, actuator target and sucker rows of `layouts`, a row each."""
        n, order = len(layouts), self._order
        body_rows = np.array([lay.body_rows for lay in layouts], dtype=np.int64)
        motor_rows = np.array([lay.actuator_motor_rows for lay in layouts], dtype=np.int64)
        axes = np.array([lay.actuator_axes for lay in layouts], dtype=np.int64)
        sucker_rows = np.array([lay.sucker_rows for lay in layouts], dtype=np.int64)
        return (
            body_rows,
            motor_rows[:, order].reshape(n, -1),
            (motor_rows * 3 + axes)[:, order].reshape(n, -1),
            sucker_rows.reshape(n, len(self.equality_ids)),
        )

    # -- roster changes (spawn, despawn) ------------------------------------------------
    def append(self, layout: ModelLayout, member: int) -> int:
        """One more creature of this morphology (roster index `member`); its row, zeroed
        (`place` it next). No other row moves."""
        if layout.key != self.key:
            raise ValueError("a creature of another morphology cannot join this batch")
        added = (*self._store_rows([layout]), np.array([member]))
        for name, value in zip(self.PER_ROW[:5], added, strict=True):
            setattr(self, name, np.concatenate([getattr(self, name), value]))
        for name in self.PER_ROW[5:]:
            array = getattr(self, name)
            fill = {"deepest": np.inf, "proxy_size": 0.01, "rslot": -1}.get(name, 0)
            grown = np.full((len(array) + 1, *array.shape[1:]), fill, dtype=array.dtype)
            grown[:-1] = array
            setattr(self, name, grown)
        if self.unplaced is not None:  # (the new row is placed next)
            self.unplaced = np.append(self.unplaced, False)
            self.placement = np.concatenate([self.placement, np.zeros((1, 7))])
        self._follow_shown(None)
        return len(self) - 1

    def remove(self, row: int) -> None:
        """Take row `row` out; the rows after it move up one (forces and errors with them)."""
        self.release_reduced(np.array([row]))
        for name in self.PER_ROW:
            setattr(self, name, without_row(getattr(self, name), row))
        self.applied = {r - (r > row): f for r, f in self.applied.items() if r != row}
        self.errors = {r - (r > row): e for r, e in self.errors.items() if r != row}
        if self.unplaced is not None:
            self.unplaced = np.delete(self.unplaced, row)
            self.placement = np.delete(self.placement, row, axis=0)
        self._follow_shown(row)

    def renumber(self, moved: dict[str, np.ndarray]) -> None:
        """Store rows moved (`ArrayStore.remove`'s answers by store name): follow them."""
        if "transforms" in moved:
            self.body_rows = moved["transforms"][self.body_rows]
        if "motors" in moved:
            motors = moved["motors"]
            self.actuator_motor_rows = motors[self.actuator_motor_rows]
            index = self.actuator_target_index
            self.actuator_target_index = motors[index // 3] * 3 + index % 3
        if "suckers" in moved:
            self.sucker_rows = moved["suckers"][self.sucker_rows]

    # -- parts of the state --------------------------------------------------------
    def part(self, flag: int, rows: slice | np.ndarray | int = slice(None)) -> np.ndarray:
        """The `flag` part (an mjtState bit) of the state of `rows` (a view for slices/ints)."""
        return self.state[rows, self.slices[int(flag)]]

    @property
    def qvel(self) -> np.ndarray:
        return self.part(S.mjSTATE_QVEL)

    @property
    def ctrl(self) -> np.ndarray:
        return self.part(S.mjSTATE_CTRL)

    def grid(self, flag: int, width: int) -> np.ndarray:
        """The `flag` part of every row as a (rows, items, width) view (mocap poses)."""
        view = self.part(flag).view()
        items = view.shape[1] // width
        view.shape = (len(self), items, width)  # raises rather than copy: writes must land
        return view

    # -- building ------------------------------------------------------------------
    def swap_model(self, model: mujoco.MjModel, reduced: Callable[[], ReducedModel] | None) -> None:
        """Step with `model` from now on: the same creature on other static ground (its
        state vector has the same layout; only the ids of the geoms after the ground's
        may move). The scratch copies are made again on the next `prepare`."""
        if mujoco.mj_stateSize(model, STATE) != self.state.shape[1]:
            raise ValueError("the new model's state differs: not the same creature")
        obj = mujoco.mjtObj
        proxies = [mujoco.mj_id2name(self.model, obj.mjOBJ_GEOM, int(g)) for g in self.proxy_geoms]
        self.proxy_geoms = _ids(model, obj.mjOBJ_GEOM, proxies)
        self.model = model
        self._full_guess = 1e-6 * (model.nv + 1.0)
        self.models = {FULL: model}
        self._compile_reduced = reduced
        self.reduced = None  # compiled again on the next `prepare` (its state rows stay)
        self.scratch = {}

    def prepare(self, tier: int, threads: int) -> None:
        """Make `tier`'s model (compiled once) and a scratch for each of `threads`.

        Call before the stepping threads run: they only read these.
        """
        if tier not in self.models:
            if tier != REDUCED or self._compile_reduced is None:
                raise ValueError(f"batch {self.index} has no model for tier {tier}")
            self._make_reduced(self._compile_reduced())
        scratch = self.scratch.setdefault(tier, [])
        while len(scratch) < threads:
            model = copy.copy(self.models[tier])
            scratch.append(Scratch(model, mujoco.MjData(model)))

    def _make_reduced(self, reduced: ReducedModel) -> None:
        reduced.name_ids(self, self.model)
        self.pose_map = PoseMap(self.model, self.body_ids)
        self.reduced = reduced
        self.models[REDUCED] = reduced.model
        width = (reduced.size, reduced.watched.stop - reduced.watched.start)
        if self.rstate.shape[1] != width[0]:  # first compile: every row fits on first step
            self.rslot[:] = -1
            self.rstate = np.zeros((0, width[0]))
            self.rsource = np.zeros((0, width[1]))

    def hold_reduced(self, rows: np.ndarray) -> None:
        """Rows `rows` (about to step REDUCED: `prepare(REDUCED)` ran) each hold a reduced
        state; a row new to it fits its full state on its first step (its `rsource`: NaN,
        which nothing equals)."""
        new = rows[self.rslot[rows] < 0]
        if not len(new):
            return
        held = len(self.rstate)
        self.rslot[new] = held + np.arange(len(new))
        self.rstate = np.concatenate([self.rstate, np.zeros((len(new), self.rstate.shape[1]))])
        self.rsource = np.concatenate(
            [self.rsource, np.full((len(new), self.rsource.shape[1]), np.nan)]
        )

    def release_reduced(self, rows: np.ndarray) -> None:
        """Rows `rows` hold no reduced state from now on (replayed ones: a promotion writes
        their full state, which they would fit again anyway); the others keep theirs."""
        gone = self.rslot[rows]
        gone = gone[gone >= 0]
        if not len(gone):
            return
        kept = np.ones(len(self.rstate), dtype=bool)
        kept[gone] = False
        self.rslot[rows] = -1
        held = self.rslot >= 0
        self.rslot[held] = (np.cumsum(kept) - 1)[self.rslot[held]]
        self.rstate, self.rsource = self.rstate[kept], self.rsource[kept]

    def frame_cost(self, rows: np.ndarray, tier: int) -> np.ndarray:
        """(len(rows),) what stepping each row at `tier` costs a frame, in seconds of a
        FULL step: the time its steps took lately (`step_cost`), or, before its first, a
        guess from the degrees of freedom. For sharing rows between threads."""
        measured = self.step_cost[rows, tier]
        if tier == REDUCED:
            nv = self.reduced.model.nv if self.reduced is not None else self.model.nv // 2
            guess, steps = 2e-6 * (nv + 1.0), 1.0 / REDUCED_RATE
        else:  # (asking MuJoCo's model for nv took 5 us right after a step)
            guess, steps = self._full_guess, 1.0
        cost = np.asarray(np.where(measured > 0.0, measured, guess))
        return cost if steps == 1.0 else cost * steps

    def scratch_for(self, thread: int, tier: int = FULL) -> Scratch:
        """Thread `thread`'s scratch model and data for `tier` (made on first use)."""
        scratch = self.scratch.get(tier)
        if scratch is None or len(scratch) <= thread:
            self.prepare(tier, thread + 1)
        return self.scratch[tier][thread]

    def standalone(self, row: int) -> tuple[mujoco.MjModel, mujoco.MjData]:
        """A new model and data of row `row` alone, as its next step would see them.

        For inspection (servo forces, contacts, a viewer): forward kinematics and
        forces are computed; writing them changes nothing in the batch.
        """
        self.place_pending(row)
        m = copy.copy(self.model)
        d = mujoco.MjData(m)
        write_overlay(self, m, row)
        if row in self.applied:
            d.xfrc_applied[:] = self.applied[row]
        mujoco.mj_setState(m, d, self.state[row], STATE)
        mujoco.mj_forward(m, d)
        return m, d

    def forward(self, row: int) -> None:
        """Recompute row `row`'s body poses from its state (after a restore)."""
        self.place_pending(row)
        scratch = self.scratch_for(0)
        m, d = scratch.model, scratch.data
        mujoco.mj_setState(m, d, self.state[row], STATE)
        mujoco.mj_forward(m, d)
        self.xpos[row] = d.xpos[self.body_ids]
        self.xquat[row] = d.xquat[self.body_ids]
        self._stepped(row)

    def step_rows(self, rows: np.ndarray, substeps: int, thread: int, tier: int = FULL) -> None:
        """Advance `rows` by `substeps` steps each of `tier`'s model, on `thread`'s scratch."""
        if tier == REDUCED:  # (`physics.reduced_step`)
            seconds, shared = step_reduced(self, rows, substeps, thread)
            running_costs(self.step_cost, rows, REDUCED, seconds, shared, substeps)
            return
        scratch = self.scratch_for(thread, tier)
        m, poses, turns = scratch.model, scratch.xpos, scratch.xquat
        state, bodies, applied = self.state, self.model_bodies, self.applied
        xpos, xquat, clock = self.xpos, self.xquat, time.perf_counter
        scratch.warnings[:] = 0  # `advance` clears them after a row that raised one
        took = []  # each row's seconds, into the running costs at once after the share
        began = clock()
        for row in rows.tolist():
            write_overlay(self, m, row)
            if self.advance(scratch, row, state[row], applied.get(row), substeps):
                xpos[row] = poses[bodies]
                xquat[row] = turns[bodies]
            ended = clock()
            took.append(ended - began)
            began = ended
        running_costs(self.step_cost, rows, FULL, np.array(took), 0.0, substeps)

    def advance(
        self,
        scratch: Scratch,
        row: int,
        vector: np.ndarray,
        forces: np.ndarray | None,
        substeps: int,
    ) -> bool:
        """Step state `vector` (row `row`'s, in `scratch`'s model layout) in place under
        `forces` (xfrc_applied, or none); warnings and the deepest contact recorded. False
        when MuJoCo failed (the error is kept for the health check; `vector` unchanged)."""
        m, d = scratch.model, scratch.data
        if forces is not None:
            d.xfrc_applied[:] = forces
            scratch.forced = True
        elif scratch.forced:
            d.xfrc_applied[:] = 0.0
            scratch.forced = False
        mujoco.mj_setState(m, d, vector, STATE)
        raised, none = scratch.warnings, scratch.no_warnings  # zero: cleared by the caller
        try:
            mujoco.mj_step(m, d, nstep=substeps)
        except mujoco.FatalError as exc:
            self.errors[row] = str(exc).splitlines()[0]
            mujoco.mj_resetData(m, d)
            return False
        mujoco.mj_getState(m, d, vector, STATE)
        if raised.tobytes() != none:  # (a bytes compare: a fifth of `.any()`'s time)
            self.warnings[row] += raised
            raised[:] = 0
        # the deepest contact (NaN, from a state gone bad, is failed by the health check's
        # velocity test first); a list's min is twice as fast as numpy's for a few contacts
        self.deepest[row] = min(d.contact.dist.tolist()) if d.ncon else np.inf
        return True


def running_costs(
    cost: np.ndarray, rows: np.ndarray, tier: int, took: np.ndarray, shared: float, substeps: int
) -> None:
    """Row rows[i]'s `substeps` steps at `tier` took took[i] + `shared` seconds: into
    `cost` (`Batch.step_cost`), a running mean (the first as it is, then 3/4 of the last
    plus 1/4 of the new); by a numba kernel when installed (a share's call spent 25 us
    in numpy's five passes over a few rows), else row by row in scalars."""
    fast = REDUCED_KERNELS.get()
    if fast is not None:
        fast.running_costs(cost, rows, tier, took, shared, substeps)
        return
    for at, row in enumerate(rows.tolist()):
        seconds = (float(took[at]) + shared) / substeps
        last = cost[row, tier]
        cost[row, tier] = seconds if last == 0.0 else 0.75 * last + 0.25 * seconds
