"""Physics health: find every blow-up, put the creature back, tell the truth.

Each frame, after the step and before poses reach the Transform store, every active
creature is checked:

* a fatal MuJoCo error in the step (a blown-up state overflowing the arena);
* any MuJoCo warning counted since the last frame (bad qacc, qpos, qvel or ctrl,
  bad inertia, a full contact or constraint buffer); MuJoCo's own auto-reset is off
  (`physics.model`), so nothing clears the counters behind our back;
* a non-finite position or velocity;
* a body faster than the scene's `max_speed`, or a contact deeper than its
  `max_penetration` (teleports and runaway servos show up here).

A failing creature is restored to a state saved at least `SAVE_EVERY` frames earlier
(two are kept, for the creatures MuJoCo steps only: until the first save every
creature's are its start state, kept once; the first save gives them to the creatures
stepped, and a replayed creature's are made when it is promoted, `restart`), its
suckers are released and its servos softened for a moment, and `creature_recovered` is
emitted with the cause.
The check runs right after `physics_sync` and puts a failing creature's rows back before
any other system runs. A creature that fails `FREEZE_AFTER` times within `FREEZE_WINDOW`
seconds is frozen where it last was good (`creature_frozen`, and one logged warning).
Other creatures are never touched: each is its own row of state. No system ever sees a
bad pose, so a teleport never reaches a goal. Finding the failures is whole-array work;
only failing creatures are visited.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import mujoco
import numpy as np

from ecs_tentacles.events import CreatureFrozen, CreatureRecovered, SuckerReleased
from ecs_tentacles.numeric.optional_kernels import OptionalKernels
from ecs_tentacles.numeric.rows import run_slice, without_row
from ecs_tentacles.numeric.slots import SlotRows
from ecs_tentacles.numeric.untouched import is_untouched, untouched_zeros
from ecs_tentacles.physics.tiers import KINEMATIC

if TYPE_CHECKING:
    from ecs_tentacles.physics.batch import Batch
    from ecs_tentacles.physics.host import PhysicsHost
    from ecs_tentacles.physics.proxies import ContactProxies
    from ecs_tentacles.physics.roster import Roster

KERNELS = OptionalKernels("ecs_tentacles.physics.frame_kernels", "ECS_TENTACLES_PHYSICS_FRAME")
log = logging.getLogger("ecs_tentacles.physics")

WARNINGS = {
    int(getattr(mujoco.mjtWarning, name)): name.removeprefix("mjWARN_").lower()
    for name in dir(mujoco.mjtWarning)
    if name.startswith("mjWARN_")
}
SAVE_EVERY = 10  # frames between saved good states
FREEZE_AFTER = 3  # failures ...
FREEZE_WINDOW = 2.0  # ... within this many seconds freeze a creature
SOFT_GAIN = 0.2  # servo gain right after a recovery, back to 1 over SOFT_SECONDS
SOFT_SECONDS = 0.5
S = mujoco.mjtState


@dataclass(frozen=True)
class HealthState:
    """The health check between frames (`HealthCheck.state()`), for snapshots."""

    saved: list[SlotRows]  # per batch: (2, state) older and newer good states per row
    failures: dict[int, list[float]]
    recoveries: int
    frozen: int
    causes: dict[str, int]
    previous: np.ndarray  # last frame's poses
    allowed: dict[int, tuple[float, float]] = field(default_factory=dict)  # `allow_speed`
    initial: list[np.ndarray | None] = field(default_factory=list)  # per batch, until saved


class HealthCheck:
    """Checks every creature after each step (whole arrays); recovers the ones that failed."""

    def __init__(self, world: PhysicsHost, roster: Roster, proxies: ContactProxies):
        self.roster = roster
        self.max_speed = world.settings.max_speed
        self.max_penetration = world.settings.max_penetration
        # per batch: two good states per row, [older, newer], held by the rows stepped by
        # MuJoCo only: a replayed (KINEMATIC) row's are made by `restart` when it is
        # promoted (10,000 creatures' were 175 MB). Until the first save both are every
        # row's start state, kept once (`initial`): the tiers are decided on the first
        # frame, and making both for every row at the build made its peak 1.8 GiB
        self.saved = [SlotRows.empty(len(b), (2, b.state.shape[1])) for b in roster.batches]
        self.initial: list[np.ndarray | None] = [_start_states(b) for b in roster.batches]
        self.failures: dict[int, list[float]] = {}  # creature index -> recent recovery times
        # creature index -> (speed m/s, until world time): a thrown creature may fly faster
        self.allowed: dict[int, tuple[float, float]] = {}
        self.recoveries = 0
        self.frozen = 0
        self.causes: dict[str, int] = {}
        # every creature's body rows, creature by creature, for whole-array speed checks
        self.follow(proxies)
        self.previous = np.zeros((0, 3))  # last frame's poses (set on the first check)

    # -- state ---------------------------------------------------------------------
    def state(self) -> HealthState:
        """A copy of what the check remembers: saved good states, failures, counts, poses."""
        return HealthState(
            [s.copy() for s in self.saved],
            {k: list(v) for k, v in self.failures.items()},
            self.recoveries,
            self.frozen,
            dict(self.causes),
            self.previous.copy(),
            dict(self.allowed),
            [None if s is None else s.copy() for s in self.initial],
        )

    def set_state(self, state: HealthState) -> None:
        """Go back to `state()` (copied: one state can be restored many times)."""
        for saved, copy in zip(self.saved, state.saved, strict=False):  # later ones: empty
            saved.set_to(copy)
        initial = [None if s is None else s.copy() for s in state.initial]
        self.initial = initial + [None] * (len(self.saved) - len(initial))
        self.failures = {k: list(v) for k, v in state.failures.items()}
        self.recoveries, self.frozen = state.recoveries, state.frozen
        self.causes = dict(state.causes)
        self.previous = state.previous.copy()
        self.allowed = dict(state.allowed)

    # -- roster changes --------------------------------------------------------------
    def grow(
        self, batch: int, state: np.ndarray, poses: np.ndarray, proxies: ContactProxies
    ) -> None:
        """A creature was appended to batch `batch` at `state`, its bodies at `poses`
        (the new rows at the Transform store's end)."""
        if batch == len(self.saved):
            self.saved.append(SlotRows(np.zeros((0, 2, len(state)))))
            self.initial.append(None)
        self.saved[batch].append(np.repeat(state[None], 2, 0))
        initial = self.initial[batch]
        if initial is not None:  # (its row holds its own: this one keeps rows aligned)
            self.initial[batch] = np.concatenate([initial, state[None]])
        if len(self.previous):
            self.previous = np.concatenate([self.previous, poses])
        self.follow(proxies)

    def remove(
        self, index: int, batch: int, row: int, kept: np.ndarray, proxies: ContactProxies
    ) -> None:
        """Creature `index` (row `row` of batch `batch`) was taken out; `kept`: which
        Transform rows are left."""
        self.saved[batch].remove(row)
        initial = self.initial[batch]
        if initial is not None:
            self.initial[batch] = without_row(initial, row)
        self.failures = {i - (i > index): times for i, times in self.failures.items() if i != index}
        self.allowed = {i - (i > index): a for i, a in self.allowed.items() if i != index}
        if len(self.previous):
            self.previous = self.previous[kept]
        self.follow(proxies)

    def follow(self, proxies: ContactProxies) -> None:
        """Read the bodies' order from `proxies` again (after it was rebuilt)."""
        self.rows = proxies.rows
        self.start, self.count = proxies.start, proxies.count
        self.span = run_slice(self.rows)  # one run of Transform rows (a crowd): a slice

    def placed(self, batch: int, rows: np.ndarray) -> None:
        """Rows `rows` of batch `batch` were placed only now (`physics.placing`): their
        state is their start state."""
        initial = self.initial[batch]
        if initial is not None:
            initial[rows] = self.roster.batches[batch].state[rows]

    def allow_speed(self, index: int, speed: float, until: float) -> None:
        """Creature `index` may move its bodies up to `speed` m/s (instead of the scene's
        `max_speed`) until world time `until`: one thrown or dragged by hand, whose
        tentacles whip faster than any crawl, is not taken for a blow-up."""
        if not speed > 0:
            raise ValueError(f"speed: must be > 0, got {speed}")
        self.allowed[index] = (float(speed), float(until))

    def restart(self, index: int) -> None:
        """Creature `index` was placed anew: its good states are where it is now."""
        roster = self.roster
        batch = roster.batches[int(roster.batch_of[index])]
        row = int(roster.row_of[index])
        self.saved[batch.index].hold(np.array([row]), batch.state[row])
        if len(self.previous):
            self.previous[batch.body_rows[row]] = batch.xpos[row]

    # -- per frame -------------------------------------------------------------------
    def check(self, world: PhysicsHost, physics_time: float) -> None:
        """Check every creature stepped this frame; recover the ones that failed.

        Runs right after `physics_sync`: speeds and non-finite poses are read from the
        Transform store as whole arrays, the rest from the batches' arrays; a failing
        creature's rows are put back before any other system reads them.
        `physics_time` is the physics clock: a recovered creature's state is set to it.
        """
        roster = self.roster
        limit: float | np.ndarray = self.max_speed * world.settings.dt
        for index, (speed, until) in list(self.allowed.items()):
            if world.time > until:
                del self.allowed[index]
            else:
                if not isinstance(limit, np.ndarray):
                    limit = np.full(len(roster), limit)
                limit[index] = max(self.max_speed, speed) * world.settings.dt
        save = world.frame % SAVE_EVERY == 0
        ramp = world.settings.dt / SOFT_SECONDS
        pos = world.transforms.pos
        if len(self.previous) != len(pos):
            self.previous = pos.copy()
        active = roster.active
        fastest = self._fastest(pos, active)
        bad = ~(fastest <= limit)  # also nan: a pose that is not finite
        fast = KERNELS.get()
        for batch in roster.batches:
            if fast is not None:  # the same faults in one pass
                fast.row_faults(batch.members, active, batch.warnings, batch.qvel,
                                batch.deepest, self.max_penetration, bad)  # fmt: skip
            else:
                stepped = active[batch.members]  # what was stepped: the rest waits
                rows = slice(None) if stepped.all() else np.flatnonzero(stepped)
                at = batch.members[rows]
                bad[at] |= batch.warnings[rows].any(axis=1)
                bad[at] |= ~np.isfinite(batch.qvel[rows]).all(axis=1)
                bad[at] |= batch.deepest[rows] < -self.max_penetration
            for row in batch.errors:
                bad[batch.members[row]] = True
        failing = np.flatnonzero(bad & active)
        dt = world.settings.dt
        causes: dict[int, str] = {}
        if len(failing):  # (rare: `broadcast_to` alone cost more than the rest of a check)
            limits = np.broadcast_to(limit, bad.shape)
            causes = {
                int(i): self._cause(int(i), float(fastest[i]), float(limits[i]), dt)
                for i in failing
            }
        healthy = active & ~bad
        softened = healthy & (roster.soften < 1.0)
        roster.soften[softened] = np.minimum(
            1.0, roster.soften[softened] + ramp * (1.0 - SOFT_GAIN)
        )
        if save:
            replayed = roster.tier == KINEMATIC
            for batch, saved, initial in zip(roster.batches, self.saved, self.initial, strict=True):
                if initial is not None:  # the first save: stepped rows hold their start
                    new = np.flatnonzero(~replayed[batch.members] & (saved.slot < 0))
                    saved.hold(new, initial[new, None])
                saved.release(np.flatnonzero(replayed[batch.members]))
                rows = np.flatnonzero(healthy[batch.members])
                slots = saved.slot[rows]
                if (slots < 0).any():  # (never: a creature is promoted through `restart`)
                    slots = saved.hold(rows, batch.state[rows, None])
                older, newer = saved.pool[:, 0], saved.pool[:, 1]
                older[slots] = newer[slots]
                newer[slots] = batch.state[rows]
            self.initial = [None] * len(self.saved)
        for batch in roster.batches:
            batch.warnings[:] = 0
            batch.errors.clear()
        for index, cause in causes.items():
            self._recover(world, index, cause, physics_time)
        self._remember(pos)

    def _remember(self, pos: np.ndarray) -> None:
        """This frame's poses as the next check's `previous`, but a replayed (KINEMATIC)
        creature's: it is never checked, and leaves the tier only through
        `PhysicsBackend.place_joints`, whose `restart` sets its rows (10,000 creatures'
        bodies were a 19 MB copy a frame). Once some are replayed, `previous` holds
        pages for the others' rows only (`numeric.untouched`: the build's copy of every
        pose was 19 MB resident at 10,000)."""
        roster = self.roster
        kept = roster.tier != KINEMATIC
        if kept.all():
            self.previous[:] = pos
            return
        if not is_untouched(self.previous):  # (the build's copy: every row)
            self.previous = untouched_zeros(pos.shape)  # resident where written from now on
        who = np.flatnonzero(kept)
        if not len(who):
            return
        fast = KERNELS.get()
        if fast is not None:  # the same copies, without the index arrays
            fast.copy_bodies(pos, self.previous, self.rows, self.start, self.count, who)
            return
        count = self.count[who]
        first = np.repeat(self.start[who] - (np.cumsum(count) - count), count)
        rows = self.rows[first + np.arange(count.sum())]
        self.previous[rows] = pos[rows]

    def _fastest(self, pos: np.ndarray, active: np.ndarray) -> np.ndarray:
        """Per creature, its fastest body's move since last frame (m; 0 if not stepped)."""
        fastest = np.zeros(len(active))
        who = np.flatnonzero(active)
        fast = KERNELS.get()
        if fast is not None:  # the same numbers in one pass
            fast.fastest_moves(pos, self.previous, self.rows, self.start, self.count, who, fastest)
            return fastest
        rows: slice | np.ndarray
        if len(who) == len(active):
            rows, start = self.rows if self.span is None else self.span, self.start
        else:
            if not len(who):
                return fastest
            count = self.count[who]
            first = np.repeat(self.start[who] - (np.cumsum(count) - count), count)
            rows = self.rows[first + np.arange(count.sum())]
            start = np.cumsum(count) - count
        moved = pos[rows] - self.previous[rows]
        x, y, z = moved[:, 0], moved[:, 1], moved[:, 2]  # nan where a pose is not finite
        step = x * x + y * y + z * z  # the kernel's order (einsum's depends on the CPU)
        if len(step):
            fastest[who] = np.sqrt(np.maximum.reduceat(step, start))
        return fastest

    def _cause(self, index: int, fastest: float, limit: float, dt: float) -> str:
        roster = self.roster
        batch = roster.batches[int(roster.batch_of[index])]
        row = int(roster.row_of[index])
        if row in batch.errors:
            return f"fatal {batch.errors[row]}"
        raised = np.flatnonzero(batch.warnings[row])
        if len(raised):
            names = sorted(WARNINGS.get(int(i), f"warning{i}") for i in raised)
            return f"mujoco {', '.join(names)}"
        if not fastest <= limit:
            if not np.isfinite(fastest):
                return "non-finite state"
            return f"speed {fastest / dt:.3g} m/s"
        if not np.isfinite(batch.qvel[row]).all():
            return "non-finite state"
        return f"penetration {-1000 * batch.deepest[row]:.1f} mm"

    def _recover(self, world: PhysicsHost, index: int, cause: str, physics_time: float) -> None:
        roster = self.roster
        batch = roster.batches[int(roster.batch_of[index])]
        row = int(roster.row_of[index])
        now = world.time
        failures = [t for t in self.failures.get(index, []) if now - t < FREEZE_WINDOW] + [now]
        self.failures[index] = failures
        key = cause.split(" ")[0]
        self.causes[key] = self.causes.get(key, 0) + 1
        saved, initial = self.saved[batch.index], self.initial[batch.index]
        slot = int(saved.slot[row])
        batch.state[row] = initial[row] if slot < 0 and initial is not None else saved.pool[slot, 0]
        batch.part(S.mjSTATE_TIME, row)[:] = physics_time
        batch.forward(row)
        world.transforms.pos[batch.body_rows[row]] = batch.xpos[row]  # before anyone reads
        world.transforms.quat[batch.body_rows[row]] = batch.xquat[row]
        roster.soften[index] = SOFT_GAIN
        batch.part(S.mjSTATE_EQ_ACTIVE, row)[:] = 0.0
        suckers = world.suckers
        rows = batch.sucker_rows[row]
        for sucker_row in rows[suckers.attached[rows]]:  # core: no feature call
            suckers.attached[sucker_row] = False
            sucker = int(suckers.entity[sucker_row])
            world.events.emit(SuckerReleased(world, sucker, "recovery"))
        creature = int(roster.entity[index])
        self.recoveries += 1
        world.events.emit(CreatureRecovered(world, creature, cause))
        if len(failures) >= FREEZE_AFTER:
            batch.part(S.mjSTATE_QVEL, row)[:] = 0.0
            roster.frozen[index] = True
            self.frozen += 1
            name = world.creature_name(creature)
            log.warning(
                "creature %r frozen: %d physics failures in %.1f s (last: %s)",
                name,
                len(failures),
                FREEZE_WINDOW,
                cause,
            )
            world.events.emit(CreatureFrozen(world, creature, cause))


def _start_states(batch: Batch) -> np.ndarray:
    """A copy of `batch`'s state rows, its start states: resident for the rows placed
    only (a row placed later is written by `HealthCheck.placed`)."""
    if batch.unplaced is None:
        return batch.state.copy()
    initial = untouched_zeros(batch.state.shape)
    placed = np.flatnonzero(~batch.unplaced)
    initial[placed] = batch.state[placed]
    return initial
