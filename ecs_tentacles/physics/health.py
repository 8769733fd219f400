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
`creature_recovered` is emitted with the cause. A creature that fails `FREEZE_AFTER`
times within `FREEZE_WINDOW` seconds is frozen where it last was good
(`creature_frozen`, and one logged warning). Other creatures are never touched: each
is its own group. Bad poses never reach the store, so a teleport never reaches a goal.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import mujoco
import numpy as np

if TYPE_CHECKING:
    from ecs_tentacles.physics.group import PhysicsGroup
    from ecs_tentacles.world import World

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


class PhysicsHealth:
    """Checks every group after each step and recovers the ones that failed."""

    def __init__(self, world: World, groups: list[PhysicsGroup]):
        self.groups = groups
        self.max_speed = world.settings.max_speed
        self.max_penetration = world.settings.max_penetration
        self.state = [GroupHealth() for _ in self.groups]
        for group, health in zip(self.groups, self.state, strict=True):
            start = group.get_state()
            health.saved = [start, start]
        self.recoveries = 0
        self.frozen = 0
        self.causes: dict[str, int] = {}
        self.recovered_frames: list[int] = []  # world frames on which a recovery happened

    def check(self, world: World) -> None:
        """Check every active group stepped this frame; recover the ones that failed."""
        limit = self.max_speed * world.settings.dt
        save = world.frame % SAVE_EVERY == 0
        ramp = world.settings.dt / SOFT_SECONDS
        pos = world.transforms.pos
        for group, health in zip(self.groups, self.state, strict=True):
            if not group.active:
                continue
            cause = self._cause(group, pos, limit)
            if cause is not None:
                self._recover(world, group, health, cause)
                continue
            if group.soften < 1.0:
                group.soften = min(1.0, group.soften + ramp * (1.0 - SOFT_GAIN))
            if save:
                health.saved = [health.saved[1], group.get_state()]

    def _cause(self, group: PhysicsGroup, pos: np.ndarray, limit: float) -> str | None:
        d = group.data
        if group.error is not None:
            cause, group.error = f"fatal {group.error}", None
            return cause
        counts = d.warning.number
        if (counts > group.warnings).any():
            raised = np.flatnonzero(counts > group.warnings)
            group.warnings[:] = counts
            names = sorted(WARNINGS.get(int(i), f"warning{i}") for i in raised)
            return f"mujoco {', '.join(names)}"
        if not (np.isfinite(d.qpos).all() and np.isfinite(d.qvel).all()):
            return "non-finite state"
        moved = d.xpos[group.body_ids] - pos[group.body_rows]
        speed = float(np.sqrt(np.einsum("ij,ij->i", moved, moved).max()))
        if not speed <= limit:
            return f"speed {speed / limit * self.max_speed:.3g} m/s"
        if d.ncon and d.contact.dist.min() < -self.max_penetration:
            return f"penetration {-1000 * d.contact.dist.min():.1f} mm"
        return None

    def _recover(self, world: World, group: PhysicsGroup, health: GroupHealth, cause: str) -> None:
        now = world.time
        health.failures = [t for t in health.failures if now - t < FREEZE_WINDOW] + [now]
        key = cause.split(" ")[0]
        self.causes[key] = self.causes.get(key, 0) + 1
        group.set_state(health.saved[0])
        group.data.time = world.physics.time
        group.warnings[:] = group.data.warning.number
        group.soften = SOFT_GAIN
        if len(group.equality_ids):
            group.data.eq_active[group.equality_ids] = 0
        suckers = world.suckers
        for row in group.sucker_rows[suckers.attached[group.sucker_rows]]:
            world.release(int(suckers.entity[row]), "recovery")
        creature = group.creatures[0]
        self.recoveries += 1
        if not self.recovered_frames or self.recovered_frames[-1] != world.frame:
            self.recovered_frames.append(world.frame)
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
