"""Idle creatures sleep: their group is not stepped until something changes.

A creature falls asleep after `SETTLE_FRAMES` frames in which no plugin wanted it to
move (`Plugin.wants_motion`: the locomotion plugin wants creatures with a goal), no
other creature near it (no contact proxies in use), no sucker attached, servo
commands that did not change (targets and gains: no writhing, no waves) and every
velocity below `STILL_SPEED`. Its state then stays exactly as it was: asleep, it is
not stepped at all, which is what makes idle crowds cheap. It wakes the frame any of
those changes (a goal, a neighbour, a script moving a target), before the step.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from ecs_tentacles.physics.group import PhysicsGroup
    from ecs_tentacles.physics.host import PhysicsHost

SETTLE_FRAMES = 30  # frames of stillness before a creature sleeps
STILL_SPEED = 1e-3  # m/s or rad/s: slower than this counts as still
COMMAND_CHANGE = 1e-9  # servo targets or gains that moved less than this did not change


@dataclass(frozen=True)
class SleepState:
    """The sleep counters between frames (`Sleep.state()`), for snapshots."""

    still: np.ndarray  # frames each group has been still
    commands: list[np.ndarray]  # each group's last servo commands


class Sleep:
    """Decides, each frame before the step, which groups sleep."""

    def __init__(self, groups: list[PhysicsGroup]):
        self.groups = groups
        self.still = np.zeros(len(groups), dtype=np.int64)  # frames each has been still
        self.commands = [np.zeros(0) for _ in groups]  # last frame's ctrl and gains
        self.enabled = True

    @property
    def asleep(self) -> int:
        """Groups asleep now."""
        return int(sum(g.sleeping for g in self.groups))

    def state(self) -> SleepState:
        """A copy of the counters and last commands."""
        return SleepState(self.still.copy(), [c.copy() for c in self.commands])

    def set_state(self, state: SleepState) -> None:
        """Go back to `state()` (copied: one state can be restored many times)."""
        self.still[:] = state.still
        self.commands = [c.copy() for c in state.commands]

    def update(self, world: PhysicsHost, wants_motion: np.ndarray | None) -> None:
        """Put still groups to sleep and wake the ones whose situation changed.

        `wants_motion` (bool per CreatureStore row, or None for nobody) says which
        creatures some plugin wants to move (`Plugin.wants_motion`): those never sleep.
        """
        if not self.enabled:  # nothing ever sleeps: no per-group work
            return
        attached = world.suckers.attached
        for group in self.groups:
            if group.frozen:
                continue
            m, d = group.model, group.data
            commands = np.concatenate((d.ctrl, m.actuator_gainprm[:, 0]))
            previous = self.commands[group.index]
            calm = (
                (wants_motion is None or not wants_motion[group.creature_row])
                and not group.proxies_used
                and not attached[group.sucker_rows].any()
                and len(previous) == len(commands)
                and float(np.abs(commands - previous).max(initial=0.0)) < COMMAND_CHANGE
            )
            self.commands[group.index] = commands
            if not calm:
                self.still[group.index] = 0
                group.sleeping = False
                continue
            if group.sleeping:
                continue
            moving = float(np.abs(d.qvel).max(initial=0.0)) >= STILL_SPEED
            self.still[group.index] = 0 if moving else self.still[group.index] + 1
            group.sleeping = bool(self.still[group.index] >= SETTLE_FRAMES)
