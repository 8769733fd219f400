"""Idle creatures sleep: their row is not stepped until something changes.

A creature falls asleep after `SETTLE_FRAMES` frames in which no plugin wanted it to
move (the `MotionWants` entries: the locomotion plugin wants creatures with a goal), no
other creature near it (no contact proxies in use), no sucker attached, servo
commands that did not change (targets and gains: no writhing, no waves) and every
velocity below `STILL_SPEED`. Its state then stays exactly as it was: asleep, it is
not stepped at all, which is what makes idle crowds cheap. It wakes the frame any of
those changes (a goal, a neighbour, a script moving a target), before the step.
The decision is whole-array work over every batch's rows.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.numeric.optional_kernels import OptionalKernels
from ecs_tentacles.numeric.rows import without_row
from ecs_tentacles.numeric.untouched import untouched_zeros

if TYPE_CHECKING:
    from ecs_tentacles.physics.host import PhysicsHost
    from ecs_tentacles.physics.roster import Roster

SETTLE_FRAMES = 30  # frames of stillness before a creature sleeps
STILL_SPEED = 1e-3  # m/s or rad/s: slower than this counts as still
COMMAND_CHANGE = 1e-9  # servo targets or gains that moved less than this did not change
# the decisions by numba when installed (`physics.frame_kernels`); =numpy: numpy
KERNELS = OptionalKernels("ecs_tentacles.physics.frame_kernels", "ECS_TENTACLES_PHYSICS_FRAME")
_NOBODY = np.zeros(0, dtype=bool)  # the kernel's `wants` when no plugin wants motion


@dataclass(frozen=True)
class SleepState:
    """The sleep counters between frames (`Sleep.state()`), for snapshots."""

    still: np.ndarray  # frames each creature has been still
    commands: list[np.ndarray]  # per batch: each row's last servo commands
    known: np.ndarray  # creatures whose last commands are known


class Sleep:
    """Decides, each frame before the step, which creatures sleep (whole arrays)."""

    def __init__(self, roster: Roster):
        self.roster = roster
        self.still = np.zeros(len(roster), dtype=np.int64)  # frames each has been still
        # written for the rows commanded only: resident there (`numeric.untouched`)
        self.commands = [untouched_zeros((len(b), 2 * b.model.nu)) for b in roster.batches]
        self.known = np.zeros(len(roster), dtype=bool)  # `commands` hold last frame's
        self.enabled = True

    @property
    def asleep(self) -> int:
        """Creatures asleep now."""
        return int(self.roster.sleeping.sum())

    def state(self) -> SleepState:
        """A copy of the counters and last commands."""
        return SleepState(self.still.copy(), [c.copy() for c in self.commands], self.known.copy())

    def set_state(self, state: SleepState) -> None:
        """Go back to `state()` (copied: one state can be restored many times)."""
        self.still[:] = state.still
        kept = [c.copy() for c in state.commands]
        self.commands = kept + self.commands[len(kept) :]  # batches compiled since: empty
        self.known[:] = state.known

    def grow(self, batch: int, width: int) -> None:
        """A creature was appended (to batch `batch`, `width` commands a row; or a new batch)."""
        self.still = np.append(self.still, 0)
        self.known = np.append(self.known, False)
        if batch == len(self.commands):
            self.commands.append(np.zeros((0, width)))
        self.commands[batch] = np.concatenate([self.commands[batch], np.zeros((1, width))])

    def remove(self, index: int, batch: int, row: int) -> None:
        """Creature `index` (row `row` of batch `batch`) was taken out."""
        self.still, self.known = np.delete(self.still, index), np.delete(self.known, index)
        self.commands[batch] = without_row(self.commands[batch], row)

    def restart(self, index: int) -> None:
        """Creature `index` was placed anew: it has not been still, its commands unknown."""
        self.still[index] = 0
        self.known[index] = False

    def update(self, world: PhysicsHost, wants_motion: np.ndarray | None) -> None:
        """Put still creatures to sleep and wake the ones whose situation changed.

        `wants_motion` (bool per CreatureStore row, or None for nobody) says which
        creatures some plugin wants to move (`MotionWants` entries): those never sleep.
        """
        if not self.enabled:  # nothing ever sleeps: no per-creature work
            return
        roster = self.roster
        attached = world.suckers.attached
        commanded = roster.commanded
        fast = KERNELS.get()
        if fast is not None:  # the same decisions, a pass a batch
            wants = _NOBODY if wants_motion is None else wants_motion
            limits = np.array([COMMAND_CHANGE, STILL_SPEED, SETTLE_FRAMES], dtype=np.float64)
            for batch, previous in zip(roster.batches, self.commands, strict=True):
                fast.sleep_rows(batch.members, commanded, roster.proxies_used, wants,
                                roster.creature_row, attached, batch.sucker_rows, batch.ctrl,
                                batch.kp, batch.qvel, previous, limits, self.known, self.still,
                                roster.sleeping)  # fmt: skip
            return
        for batch, previous in zip(roster.batches, self.commands, strict=True):
            members = batch.members
            stepped = commanded[members]
            every = bool(stepped.all())
            rows: slice | np.ndarray = slice(None) if every else np.flatnonzero(stepped)
            who = members[rows]
            if not len(who):
                continue
            ctrl, kp = batch.ctrl[rows], batch.kp[rows]
            # the cheap tests first; the commands are compared only where they still decide
            calm = ~roster.proxies_used[who].astype(bool) & self.known[who]
            if wants_motion is not None:
                calm &= ~wants_motion[roster.creature_row[who]]
            if calm.any():
                calm &= ~attached[batch.sucker_rows[rows]].any(axis=1)
            if calm.any():
                commands = np.concatenate((ctrl[calm], kp[calm]), axis=1)
                last = previous[rows][calm]
                changed = ~(np.abs(commands - last).max(axis=1, initial=0.0) < COMMAND_CHANGE)
                calm[np.flatnonzero(calm)[changed]] = False
            nu = ctrl.shape[1]
            previous[rows, :nu], previous[rows, nu:] = ctrl, kp
            self.known[who] = True
            restless = who[~calm]
            self.still[restless] = 0
            roster.sleeping[restless] = False
            settling = calm & ~roster.sleeping[who]
            if not settling.any():
                continue
            qvel = batch.qvel[rows][settling]
            moving = np.abs(qvel).max(axis=1, initial=0.0) >= STILL_SPEED
            them = who[settling]
            self.still[them] = np.where(moving, 0, self.still[them] + 1)
            roster.sleeping[them] = self.still[them] >= SETTLE_FRAMES
