"""The physics of a world: shared models, per-creature state in arrays, stepping threads.

Built once per scene (`PhysicsBackend(world)`): creatures of one morphology form one
`Batch` (`ecs_tentacles.physics.batch`) around one compiled model (`compiles` counts
them); each creature is a row of its batch's arrays and has an index in this backend's
per-creature arrays (`frozen`, `sleeping`, `soften`, `proxies_used`), in entity order.
Per frame only whole-array work runs here: `write_controls` (motor targets into every
row's ctrl, gains and torque limits into the overlay), `write_suckers` (sucker
switches and anchors), `step` (every awake row advanced on the stepping threads, each
thread with its own scratch MjData per batch) and `sync` (body poses scattered into
the Transform store). Systems stay whole-array and never see a MuJoCo object. Every
`heap.TRIM_FRAMES` frames `step` gives the C heap's free pages back, and building one fixes
glibc's thresholds (`ecs_tentacles.physics.heap`): the frames' numpy temporaries would otherwise
leave a long run growing.

`state()` / `set_state()` copy everything that decides how the physics steps on
(every batch's state rows and forces: `physics.batch_state`; the health check's memory,
the sleep counters, the per-creature flags, the clock): `ecs_tentacles.snapshot` saves
and restores the physics through them alone. The backend sees a world as `PhysicsHost`
(`physics.host`).
"""

from __future__ import annotations

import functools
import os
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import TYPE_CHECKING

import mujoco
import numpy as np

from ecs_tentacles.components import Creature, Transform
from ecs_tentacles.numeric.optional_kernels import OptionalKernels
from ecs_tentacles.physics import batch_state, heap, stepping
from ecs_tentacles.physics.bare import BareFrame, step_captured
from ecs_tentacles.physics.batch import Batch
from ecs_tentacles.physics.batch_state import BatchState
from ecs_tentacles.physics.blas import quiet_blas
from ecs_tentacles.physics.health import SOFT_GAIN, HealthCheck, HealthState
from ecs_tentacles.physics.lod import LevelOfDetail
from ecs_tentacles.physics.membership import Membership, compile_models
from ecs_tentacles.physics.messages import route_mujoco_messages
from ecs_tentacles.physics.model import ModelLayout, model_layout
from ecs_tentacles.physics.placing import place_stepped
from ecs_tentacles.physics.proxies import ContactProxies
from ecs_tentacles.physics.roster import Roster
from ecs_tentacles.physics.rounds import Ready, Rounds, round_steps
from ecs_tentacles.physics.sleep import Sleep, SleepState
from ecs_tentacles.physics.stepping import Segment, Work, hold_reduced, plan, step_segments
from ecs_tentacles.physics.tiers import FULL, KINEMATIC, REDUCED, reduced_substeps
from ecs_tentacles.physics.view import CreatureViews

if TYPE_CHECKING:
    from ecs_tentacles.physics.host import PhysicsHost
    from ecs_tentacles.store import MotorStore, SuckerStore, TransformStore

KERNELS = OptionalKernels("ecs_tentacles.physics.frame_kernels", "ECS_TENTACLES_PHYSICS_FRAME")
S = mujoco.mjtState
PLACE_LATE = True  # a replayable crowd's rows placed when first stepped (False: at the build)
# rounds in which no near creature steps are left out, with the proxies' catch-up before
# them (False: every round, as when a FULL creature is near)
SKIP_IDLE_ROUNDS = True


@dataclass(frozen=True)
class PhysicsState:
    """The whole physics between frames (`PhysicsBackend.state()`); opaque to callers."""

    time: float
    batches: list[BatchState]  # per batch (`physics.batch_state`)
    frozen: np.ndarray
    sleeping: np.ndarray
    soften: np.ndarray
    tier: np.ndarray
    lod: tuple[np.ndarray, ...]
    health: HealthState
    sleep: SleepState


class PhysicsBackend(Membership):
    """Every creature's physics: batches of shared models, stepped on a thread pool;
    creatures join and leave it while it runs (`Membership`: `add_creature`,
    `remove_creature`)."""

    def __init__(self, world: PhysicsHost, threads: int | None = None):
        route_mujoco_messages()
        heap.settle()  # a long run must not grow (`ecs_tentacles.physics.heap`)
        self.threads = max(1, threads if threads is not None else os.cpu_count() or 1)
        self.time = 0.0
        creatures = sorted(world.query(Creature, Transform))
        by_key: dict[tuple[object, ...], list[int]] = {}
        layouts: list[ModelLayout] = []
        for index, (_, (creature, transform)) in enumerate(creatures):
            layout = model_layout(world, creature, transform)
            layouts.append(layout)
            by_key.setdefault(layout.key, []).append(index)
        self.roster = roster = Roster(
            np.array([e for e, _ in creatures], dtype=np.int64),
            np.array([c.row for _, (c, _) in creatures], dtype=np.int64),
        )
        self.batches = roster.batches
        # a crowd the level of detail may replay from the first frame: its rows are
        # shown at the build and placed when first stepped (`physics.placing`)
        lod = world.settings.lod
        late = PLACE_LATE and lod.enabled and len(creatures) > lod.full
        for indices in by_key.values():
            model, reduced = compile_models(world, creatures[indices[0]][1][0])
            batch = Batch(len(self.batches), model, [layouts[i] for i in indices], reduced)
            roster.add(batch, indices)
            batch.prepare(FULL, self.threads)  # every thread's scratch, before threads run
            mantles = [creatures[i][1][1] for i in indices]
            batch.place_all(np.array([t.pos for t in mantles]), np.array([t.quat for t in mantles]),
                            world.transforms if late else None)  # fmt: skip
        self.compiles = len(self.batches)
        self.view_of_creature_row = np.zeros(0, dtype=np.int64)
        self.views = CreatureViews(self.roster)
        self._index_views(len(world.creatures))
        self.proxies = ContactProxies(roster)
        self.health = HealthCheck(world, roster, self.proxies)
        for batch in self.batches:  # a row placed late starts the health check's memory
            batch.when_placed = functools.partial(self.health.placed, batch.index)
        self.sleep = Sleep(roster)
        self.sleep.enabled = world.settings.sleep
        settings = world.settings
        self.lod = LevelOfDetail(
            roster, self.proxies, settings.lod, settings.fps, self.place_joints
        )
        self._pool = ThreadPoolExecutor(self.threads) if self.threads > 1 else None
        if self._pool is not None:
            quiet_blas()  # spinning BLAS threads would take the stepping threads' cores
        self._untrimmed = 0  # frames stepped since the C heap was last trimmed

    # per creature, in entity order: the roster's arrays (replaced when creatures come
    # and go, so read through these, never kept)
    creature_entity = property(lambda self: self.roster.entity)
    creature_row = property(lambda self: self.roster.creature_row)
    batch_of = property(lambda self: self.roster.batch_of)
    row_of = property(lambda self: self.roster.row_of)
    frozen = property(lambda self: self.roster.frozen)
    sleeping = property(lambda self: self.roster.sleeping)
    soften = property(lambda self: self.roster.soften)
    proxies_used = property(lambda self: self.roster.proxies_used)
    tier = property(lambda self: self.roster.tier)

    def rebuild_models(self, world: PhysicsHost) -> None:
        """Compile every morphology's model again (the static ground changed: terrain
        edits), keeping every creature's state: no creature moves, nothing is rebuilt but
        the models and the stepping threads' copies of them. A batch whose creatures were
        all despawned is retired (no creature of it is left to build it from): the next
        creature of its shape gets a new one."""
        for batch in self.batches:
            if not len(batch):
                batch.key = None
                continue
            entity = int(self.creature_entity[batch.members[0]])
            batch.swap_model(*compile_models(world, world.component(entity, Creature)))
            batch.prepare(FULL, self.threads)

    def __len__(self) -> int:
        return len(self.creature_entity)

    # -- state -----------------------------------------------------------------------
    def state(self) -> PhysicsState:
        """A copy of the physics' state: restoring it steps on bit-identically."""
        return PhysicsState(
            time=self.time,
            batches=[batch_state.saved(b) for b in self.batches],
            frozen=self.frozen.copy(),
            sleeping=self.sleeping.copy(),
            soften=self.soften.copy(),
            tier=self.tier.copy(),
            lod=self.lod.state(),
            health=self.health.state(),
            sleep=self.sleep.state(),
        )

    def state_problem(self, state: PhysicsState) -> str | None:
        """Why `set_state(state)` would not fit this backend (one line), or None."""
        later = self.batches[len(state.batches) :]  # models compiled since for spawns
        if len(state.batches) > len(self.batches) or any(len(b) for b in later):
            return f"{len(state.batches)} physics batches, here {len(self.batches)}"
        for batch, saved in zip(self.batches, state.batches, strict=False):
            if (problem := batch_state.problem(batch, saved)) is not None:
                return problem
        if state.tier.shape != self.tier.shape:
            return f"{len(state.tier)} creatures, here {len(self.tier)}"
        return None

    def set_state(self, state: PhysicsState) -> None:
        """Go back to `state()` of this backend (same creatures); it stays reusable.

        Warnings counted since and a pending fatal error are dropped: neither is state.
        """
        self.time = state.time
        for batch, saved in zip(self.batches, state.batches, strict=False):
            batch_state.restore(batch, saved)  # (batches compiled since are empty)
        self.frozen[:], self.sleeping[:] = state.frozen, state.sleeping
        self.soften[:], self.tier[:] = state.soften, state.tier
        self.lod.set_state(state.lod)
        self.health.set_state(state.health)
        self.sleep.set_state(state.sleep)
        self.proxies.forget_posed()  # the replayed poses' spheres: the store goes back too

    # -- per frame -------------------------------------------------------------------
    def kinematic_creatures(self, creatures: int) -> np.ndarray:
        """(creatures,) bool by creature-store row: replayed, not simulated, as the last
        frame decided (systems that only feed the physics may skip them)."""
        out = np.zeros(creatures, dtype=bool)
        out[self.roster.creature_row] = self.tier == KINEMATIC
        return out

    def place_stepped(self) -> None:
        """Place the rows the build only showed that are not replayed (`physics.placing`)."""
        place_stepped(self.batches, self.tier)

    def write_controls(self, motors: MotorStore) -> None:
        """Targets into `ctrl`; kp = strength x gain, kv = damping x gain; torque limits."""
        target = motors.target.reshape(-1)
        strength, gain, damping = motors.strength, motors.gain, motors.damping
        fast = KERNELS.get()
        commanded = self.roster.commanded
        for batch in self.batches:
            live = commanded[batch.members]
            soften = self.soften[batch.members]
            if fast is not None:  # the same numbers in one pass, live rows only
                fast.servo_commands(target, batch.actuator_target_index, strength, gain, damping,
                                    motors.max_torque, batch.actuator_motor_rows, soften,
                                    np.flatnonzero(live), batch.ctrl, batch.kp, batch.kv,
                                    batch.torque)  # fmt: skip
                continue
            if live.all():
                rows = batch.actuator_motor_rows
                batch.ctrl[:] = np.take(target, batch.actuator_target_index, mode="clip")
                batch.kp[:] = strength[rows] * gain[rows] * soften[:, None]
                batch.kv[:] = damping[rows] * gain[rows]
                batch.torque[:] = motors.max_torque[rows]
                continue
            # a frozen creature keeps what it had when it froze; a kinematic one gets its
            # commands the frame it is promoted (the level of detail decides first); only
            # the live rows' products are formed (a crowd's motors are mostly replayed)
            live = np.flatnonzero(live)
            rows = batch.actuator_motor_rows[live]
            ctrl = np.take(target, batch.actuator_target_index[live], mode="clip")
            batch.state[live, batch.slices[int(S.mjSTATE_CTRL)]] = ctrl
            batch.kp[live] = strength[rows] * gain[rows] * soften[live, None]
            batch.kv[live] = damping[rows] * gain[rows]
            batch.torque[live] = motors.max_torque[rows]

    def write_suckers(self, suckers: SuckerStore) -> None:
        """Switch sucker equalities on/off and place their world anchors."""
        commanded = self.roster.commanded
        fast = KERNELS.get()
        for batch in self.batches:
            if not len(batch.equality_ids):
                continue
            live = np.flatnonzero(commanded[batch.members])
            if fast is not None:  # the same values in one pass, no gathered copies
                first = batch.slices[int(S.mjSTATE_EQ_ACTIVE)].start
                fast.sucker_switches(live, batch.sucker_rows, suckers.anchor, suckers.attached,
                                     batch.anchor, batch.state, first)  # fmt: skip
                continue
            rows = batch.sucker_rows[live]
            batch.anchor[live] = suckers.anchor[rows]
            switches = suckers.attached[rows].astype(np.float64)
            batch.state[live, batch.slices[int(S.mjSTATE_EQ_ACTIVE)]] = switches

    @property
    def active(self) -> np.ndarray:
        """Creatures stepped this frame (not frozen, not asleep, not kinematic)."""
        return self.roster.active

    def place_joints(self, index: int, qpos: np.ndarray, qvel: np.ndarray) -> None:
        """Start creature `index` from `qpos` / `qvel` (a promotion from replayed poses).

        The warm start is cleared, the poses recomputed, and the health check's saved
        states and the sleep counters restart from here. Its servos start soft and
        stiffen over `health.SOFT_SECONDS`, as after a recovery: what the controller asks
        need not match the pose it was shown in, and it must not yank.
        """
        batch = self.batches[int(self.batch_of[index])]
        row = int(self.row_of[index])
        batch.place_pending(row)  # (its controls, switches and proxies as the build's)
        batch.part(S.mjSTATE_QPOS, row)[:] = qpos
        batch.part(S.mjSTATE_QVEL, row)[:] = qvel
        batch.part(S.mjSTATE_WARMSTART, row)[:] = 0.0
        batch.part(S.mjSTATE_TIME, row)[:] = self.time
        batch.forward(row)
        self.health.restart(index)
        self.sleep.restart(index)
        self.sleeping[index] = False
        self.soften[index] = SOFT_GAIN

    def step(
        self,
        substeps: int,
        before_substep: Callable[[int], None] | None = None,
        rounds: int = 1,
        between: Callable[[Ready], None] | None = None,
    ) -> None:
        """Advance every active creature `substeps` steps; `before_substep(i)` runs first if given.

        Without hooks, creatures near another (contact proxies placed) take their steps
        in `rounds` batches with `between(ready)` called between them (their proxies
        catch up within the frame; `ready(creatures)` before it reads or writes those
        creatures' rows, `physics.rounds`); every other creature takes all its steps at
        once, on whichever thread the rounds leave idle, which gives the same result
        (nothing it reads changes between rounds) for less bookkeeping. A round in which
        none of the near creatures steps (a REDUCED one takes its step or two in one of
        them) is left out with the `between` before it (`SKIP_IDLE_ROUNDS`): what a
        catch-up reads has not moved since the frame's proxies were placed, or nothing
        steps after it (the next frame places every proxy again). A creature's
        step reads only its own row, so the result does not depend on the number of
        threads. Asleep or frozen creatures keep their state; the clock moves on.
        """
        self.place_stepped()  # (done after the level of detail decided: none left here)
        reduced = reduced_substeps(substeps)
        hold_reduced(self.batches, self.active, self.tier, self.threads)
        if before_substep is not None:
            segments = plan(self.batches, self.active, self.tier, self.threads)
            for i in range(substeps):
                before_substep(i)
                self._run(segments, {FULL: 1, REDUCED: int(i < reduced)})
        else:
            near = self.proxies_used > 0 if rounds > 1 else np.zeros(len(self), dtype=bool)
            near &= self.active
            alone = self.active & ~near
            whole = {FULL: substeps, REDUCED: reduced}
            if not near.any():
                self._run(plan(self.batches, alone, self.tier, self.threads), whole)
            else:
                stepping = np.unique(self.tier[near]).tolist() if SKIP_IDLE_ROUNDS else None
                parts = round_steps(substeps, reduced, rounds, stepping)
                self._step_rounds(near, alone, whole, parts, between)
        self.time += substeps * self.substep_dt
        self._untrimmed += 1
        if self._untrimmed >= heap.TRIM_FRAMES:
            self._untrimmed = 0
            heap.trim()

    def _step_rounds(
        self,
        near: np.ndarray,
        rest: np.ndarray,
        rest_steps: dict[int, int],
        parts: list[dict[int, int]],
        between: Callable[[Ready], None] | None,
    ) -> None:
        """The `near` creatures' steps in `parts` with `between(ready)` between them, the
        `rest` (bool per creature) stepped whole by `rest_steps` on whichever thread the
        rounds leave idle (`physics.rounds`)."""
        helpers = self.threads - 1 if self._pool is not None else 0
        segments = plan(self.batches, near, self.tier, self.threads)
        rounds = Rounds(plan(self.batches, rest, self.tier, self.threads), rest_steps, helpers + 1)

        def ready(creatures: np.ndarray) -> None:
            if not rounds.settled and rest[creatures].any():
                rounds.settle()

        pool = self._pool
        futures = [pool.submit(rounds.helper, k) for k in range(1, helpers + 1)] if pool else []
        try:
            for index, part in enumerate(parts):
                if index and between is not None:
                    between(ready)
                rounds.round(segments, part)
            rounds.settle()
        finally:
            rounds.close()
            for future in futures:
                future.result()

    def _run(self, segments: list[Segment], substeps: dict[int, int]) -> None:
        self._dispatch(step_segments, segments, substeps)

    def _dispatch(self, step: Callable[..., None], segments: list[Segment], *args: object) -> None:
        """`step(work, *args, thread)` on this thread and every pool thread at once, each
        taking shares of `segments` from one shared `Work` until none is left (this
        thread steps too instead of waiting idle; thread k always uses scratch k, and
        which thread steps a row changes nothing)."""
        helpers = min(self.threads, sum(len(s.rows) for s in segments)) - 1
        if self._pool is None or helpers < 1:
            step(Work(segments, 1), *args, 0)
            return
        work = Work(segments, helpers + 1)
        futures = [self._pool.submit(step, work, *args, thread) for thread in range(1, helpers + 1)]
        try:
            step(work, *args, 0)
        finally:
            for future in futures:
                future.result()

    def share(self, count: int, work: Callable[[int, int], None], least: int | None = None) -> None:
        """`work(start, stop)` over items [0, count) shared by the stepping threads, the
        same result as `work(0, count)` (`physics.stepping.share`: nogil work between
        steps whose items are independent; chunks of `least` or `SHARE_LEAST` items)."""
        chunk = stepping.SHARE_LEAST if least is None else least
        stepping.share(self._pool, self.threads, count, work, chunk)

    def step_bare(self, frame: BareFrame, substeps: int) -> None:
        """Step `frame`'s rows (captured by `physics.bare.FrameCapture`) with MuJoCo alone on
        this pool: nothing of the framework and nothing of the world's state, so the
        framework's cost is a frame minus this. `frame` can be stepped again."""
        segments = plan(self.batches, frame.active, frame.tier, self.threads)
        steps = {FULL: substeps, REDUCED: reduced_substeps(substeps)}
        self._dispatch(step_captured, segments, frame, steps)

    def sync(self, transforms: TransformStore) -> None:
        """Copy every body's world pose into the Transform store (one scatter per batch)."""
        for batch in self.batches:
            batch.sync(transforms)

    # -- queries ---------------------------------------------------------------------
    @property
    def substep_dt(self) -> float:
        return float(self.batches[0].model.opt.timestep) if self.batches else 0.0

    @property
    def bodies(self) -> int:
        """Creature bodies in all batches (proxies not counted)."""
        return int(sum(len(b) * len(b.body_ids) for b in self.batches))

    @property
    def dofs(self) -> int:
        return int(sum(len(b) * b.model.nv for b in self.batches))

    def close(self) -> None:
        """Stop the thread pool."""
        if self._pool is not None:
            self._pool.shutdown(wait=True)
            self._pool = None

    def __repr__(self) -> str:
        return (
            f"<physics: {len(self)} creatures, {self.compiles} compiled models,"
            f" {self.threads} threads>"
        )
