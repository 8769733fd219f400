"""Physics health: find every blow-up, put the creature back, tell the truth.

Each frame, after the step and before poses reach the Transform store, every active
group is checked:

* a fatal MuJoCo error in the step (a blown-up state overflowing the arena);
* any MuJoCo warning counted since the last frame (bad qacc, qpos, qvel or ctrl,
  bad inertia, a full contact or constraint buffer); MuJoCo's own auto-reset is off
  (`physics.model`), so nothing clears the counters behind our back;
* a non-finite position or velocity;
* a body faster than the scene's `max_speed`, or a contact deeper than its
  `max_penetration` (teleports and runaway servos show up here).

A failing creature is restored to a state saved at least `SAVE_EVERY` frames earlier
(two are kept), its suckers are released and its servos softened for a moment, and
`creature_recovered` is emitted with the cause. The check runs right after
`physics_sync` and puts a failing creature's rows back before any other system runs.
A creature that fails `FREEZE_AFTER`
times within `FREEZE_WINDOW` seconds is frozen where it last was good
(`creature_frozen`, and one logged warning). Other creatures are never touched: each
is its own group. No system ever sees a bad pose, so a teleport never reaches a goal.
"""

from __future__ import annotations

import copy
import logging
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import mujoco
import numpy as np

if TYPE_CHECKING:
    from ecs_tentacles.physics.group import PhysicsGroup
    from ecs_tentacles.physics.host import PhysicsHost

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


@dataclass
class GroupHealth:
    """What the health check remembers about one group."""

    saved: list[np.ndarray] = field(default_factory=list)  # [older, newer] good states
    failures: list[float] = field(default_factory=list)  # times of recent recoveries


@dataclass(frozen=True)
class HealthState:
    """The health check between frames (`HealthCheck.state()`), for snapshots."""

    groups: list[GroupHealth]
    recoveries: int
    frozen: int
    causes: dict[str, int]
    previous: np.ndarray  # last frame's poses


class HealthCheck:
    """Checks every group after each step and recovers the ones that failed."""

    def __init__(self, world: PhysicsHost, groups: list[PhysicsGroup]):
        self.groups = groups
        self.max_speed = world.settings.max_speed
        self.max_penetration = world.settings.max_penetration
        self.group_health = [GroupHealth() for _ in self.groups]
        for group, health in zip(self.groups, self.group_health, strict=True):
            start = group.integration_state()
            health.saved = [start, start]
        self.recoveries = 0
        self.frozen = 0
        self.causes: dict[str, int] = {}
        # every group's store rows, group by group, for whole-array speed checks
        empty = np.zeros(0, dtype=np.int64)
        self.rows = np.concatenate([g.body_rows for g in groups]) if groups else empty
        counts = [len(g.body_rows) for g in groups]
        self.start = np.concatenate([[0], np.cumsum(counts)[:-1]]).astype(np.int64)
        self.previous = np.zeros((0, 3))  # last frame's poses (set on the first check)

    # -- state ---------------------------------------------------------------------
    def state(self) -> HealthState:
        """A copy of what the check remembers: saved good states, failures, counts, poses."""
        return HealthState(
            copy.deepcopy(self.group_health),
            self.recoveries,
            self.frozen,
            dict(self.causes),
            self.previous.copy(),
        )

    def set_state(self, state: HealthState) -> None:
        """Go back to `state()` (copied: one state can be restored many times)."""
        self.group_health = copy.deepcopy(state.groups)
        self.recoveries, self.frozen = state.recoveries, state.frozen
        self.causes = dict(state.causes)
        self.previous = state.previous.copy()

    # -- per frame -------------------------------------------------------------------
    def check(self, world: PhysicsHost, physics_time: float) -> None:
        """Check every active group stepped this frame; recover the ones that failed.

        Runs right after `physics_sync`: speeds and non-finite poses are read from the
        Transform store as whole arrays; a failing group's rows are put back before any
        other system reads them. `physics_time` is the physics clock: a recovered
        group's data is set to it.
        """
        limit = self.max_speed * world.settings.dt
        save = world.frame % SAVE_EVERY == 0
        ramp = world.settings.dt / SOFT_SECONDS
        pos = world.transforms.pos
        if len(self.previous) != len(pos):
            self.previous = pos.copy()
        moved = pos[self.rows] - self.previous[self.rows]
        step = np.einsum("ij,ij->i", moved, moved)  # nan where a pose is not finite
        fastest = np.sqrt(np.maximum.reduceat(step, self.start)) if len(step) else step
        for group, health in zip(self.groups, self.group_health, strict=True):
            if not group.active:
                continue
            cause = self._cause(group, float(fastest[group.index]), limit)
            if cause is not None:
                self._recover(world, group, health, cause, physics_time)
                continue
            if group.soften < 1.0:
                group.soften = min(1.0, group.soften + ramp * (1.0 - SOFT_GAIN))
            if save:
                health.saved = [health.saved[1], group.integration_state()]
        self.previous[:] = pos

    def _cause(self, group: PhysicsGroup, fastest: float, limit: float) -> str | None:
        d = group.data
        if group.error is not None:
            cause, group.error = f"fatal {group.error}", None
            return cause
        counts = d.warning.number
        if int(counts.sum()) != group.warning_total:
            raised = np.flatnonzero(counts > group.warnings)
            group.warnings[:] = counts
            group.warning_total = int(counts.sum())
            names = sorted(WARNINGS.get(int(i), f"warning{i}") for i in raised)
            return f"mujoco {', '.join(names)}"
        if not fastest <= limit:  # also nan: a pose that is not finite
            if not np.isfinite(fastest):
                return "non-finite state"
            return f"speed {fastest / limit * self.max_speed:.3g} m/s"
        if not np.isfinite(d.qvel.sum()):
            return "non-finite state"
        if d.ncon and d.contact.dist.min() < -self.max_penetration:
            return f"penetration {-1000 * d.contact.dist.min():.1f} mm"
        return None

    def _recover(
        self,
        world: PhysicsHost,
        group: PhysicsGroup,
        health: GroupHealth,
        cause: str,
        physics_time: float,
    ) -> None:
        now = world.time
        health.failures = [t for t in health.failures if now - t < FREEZE_WINDOW] + [now]
        key = cause.split(" ")[0]
        self.causes[key] = self.causes.get(key, 0) + 1
        group.set_integration_state(health.saved[0])
        group.data.time = physics_time
        group.warnings[:] = group.data.warning.number
        group.warning_total = int(group.warnings.sum())
        group.sync(world.transforms)  # its rows, before any other system reads them
        group.soften = SOFT_GAIN
        if len(group.equality_ids):
            group.data.eq_active[group.equality_ids] = 0
        suckers = world.suckers
        for row in group.sucker_rows[suckers.attached[group.sucker_rows]]:  # core: no feature call
            suckers.attached[row] = False
            sucker = int(suckers.entity[row])
            world.events.emit("sucker_released", world=world, sucker=sucker, reason="recovery")
        creature = group.creatures[0]
        self.recoveries += 1
        world.events.emit("creature_recovered", world=world, creature=creature, cause=cause)
        if len(health.failures) >= FREEZE_AFTER:
            group.data.qvel[:] = 0.0
            group.frozen = True
            self.frozen += 1
            name = world.creature_name(creature)
            log.warning(
                "creature %r frozen: %d physics failures in %.1f s (last: %s)",
                name,
                len(health.failures),
                FREEZE_WINDOW,
                cause,
            )
            world.events.emit("creature_frozen", world=world, creature=creature, cause=cause)
