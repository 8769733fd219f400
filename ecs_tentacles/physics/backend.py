"""The physics groups of a world, stepped in parallel, with store-row index maps.

Built once per scene (`PhysicsBackend(world)`): every creature becomes a physics
group (`ecs_tentacles.physics.group`); creatures of one morphology share one compiled
model (`compiles` counts the compilations). Per frame only array copies run:
`write_controls` (motor targets and gains scattered to every group), `write_suckers`
(equality switches and anchors), `step` (`mj_step` x substeps for every active group,
on a thread pool: MuJoCo releases the GIL) and `sync` (body poses gathered back into
the Transform store). Systems stay whole-array and never see the groups.

`state()` / `set_state()` copy everything that decides how the physics steps on
(each group's integration state and flags, the health check's memory, the sleep
counters, the clock): `ecs_tentacles.snapshot` saves and restores the physics
through them alone. The backend sees a world as `PhysicsHost` (`physics.host`).
"""

from __future__ import annotations

import itertools
import logging
import os
from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import TYPE_CHECKING, Protocol

import mujoco
import numpy as np

from ecs_tentacles.components import Creature, Transform
from ecs_tentacles.physics.group import GroupState, PhysicsGroup
from ecs_tentacles.physics.health import HealthCheck, HealthState
from ecs_tentacles.physics.model import build_spec, model_layout
from ecs_tentacles.physics.proxies import ContactProxies
from ecs_tentacles.physics.sleep import Sleep, SleepState

if TYPE_CHECKING:
    from ecs_tentacles.physics.host import PhysicsHost
    from ecs_tentacles.store import MotorStore, SuckerStore, TransformStore

log = logging.getLogger("ecs_tentacles.mujoco")


def _log_mujoco_warning(message: str) -> None:
    log.warning("%s", message.strip())


def route_mujoco_messages() -> None:
    """Send MuJoCo's warnings to `logging`, never to MUJOCO_LOG.TXT in the working folder."""
    mujoco.set_mju_user_warning(_log_mujoco_warning)


@dataclass(frozen=True)
class PhysicsState:
    """The whole physics between frames (`PhysicsBackend.state()`); opaque to callers."""

    time: float
    groups: list[GroupState]
    health: HealthState
    sleep: SleepState


class PhysicsBackend:
    """Every creature's physics group, the thread pool that steps them, and index maps."""

    def __init__(self, world: PhysicsHost, threads: int | None = None):
        route_mujoco_messages()
        self.threads = max(1, threads if threads is not None else os.cpu_count() or 1)
        self.compiles = 0
        self.time = 0.0
        templates: dict[tuple, mujoco.MjModel] = {}
        self.groups: list[PhysicsGroup] = []
        for entity, (creature, transform) in sorted(world.query(Creature, Transform)):
            layout = model_layout(world, creature, transform)
            template = templates.get(layout.key)
            if template is None:
                template = templates[layout.key] = build_spec(world, creature).compile()
                self.compiles += 1
            pose = (np.array(transform.pos), np.array(transform.quat))
            group = PhysicsGroup(len(self.groups), entity, creature.row, layout, template, pose)
            self.groups.append(group)
        self.group_of_creature_row = np.full(len(world.creatures), -1, dtype=np.int64)
        for group in self.groups:
            self.group_of_creature_row[group.creature_row] = group.index
        self.proxies = ContactProxies(self.groups)
        self.health = HealthCheck(world, self.groups)
        self.sleep = Sleep(self.groups)
        self.sleep.enabled = world.settings.sleep
        self._pool = ThreadPoolExecutor(self.threads) if self.threads > 1 else None

    # -- state -----------------------------------------------------------------------
    def state(self) -> PhysicsState:
        """A copy of the physics' state: restoring it steps on bit-identically."""
        return PhysicsState(
            time=self.time,
            groups=[group.state() for group in self.groups],
            health=self.health.state(),
            sleep=self.sleep.state(),
        )

    def set_state(self, state: PhysicsState) -> None:
        """Go back to `state()` of this backend (same groups); it stays reusable."""
        self.time = state.time
        for group, saved in zip(self.groups, state.groups, strict=True):
            group.set_state(saved)
        self.health.set_state(state.health)
        self.sleep.set_state(state.sleep)

    # -- per frame -------------------------------------------------------------------
    def write_controls(self, motors: MotorStore) -> None:
        """Targets into `ctrl`; kp = strength x gain, kv = damping x gain; torque limits."""
        target = motors.target.reshape(-1)
        kp_all = motors.strength * motors.gain
        kv_all = motors.damping * motors.gain
        torque_all = motors.max_torque
        for group in self.groups:
            if group.frozen:
                continue
            m, rows = group.model, group.actuator_motor_rows
            np.take(target, group.actuator_target_index, out=group.data.ctrl, mode="clip")
            kp = kp_all[rows] * group.soften if group.soften != 1.0 else kp_all[rows]
            m.actuator_gainprm[:, 0] = kp
            m.actuator_biasprm[:, 1] = -kp
            m.actuator_biasprm[:, 2] = -kv_all[rows]
            torque = torque_all[rows]
            m.actuator_forcerange[:, 0] = -torque
            m.actuator_forcerange[:, 1] = torque

    def write_suckers(self, suckers: SuckerStore) -> None:
        """Switch sucker equalities on/off and place their world anchors."""
        anchor, attached = suckers.anchor, suckers.attached
        for group in self.groups:
            if not len(group.equality_ids) or group.frozen:
                continue
            rows = group.sucker_rows
            group.model.eq_data[group.equality_ids, 3:6] = anchor[rows]
            group.data.eq_active[group.equality_ids] = attached[rows]

    def step(
        self,
        substeps: int,
        before_substep: Callable[[int], None] | None = None,
        rounds: int = 1,
        between: Callable[[], None] | None = None,
    ) -> None:
        """Advance every active group `substeps` steps; `before_substep(i)` runs first if given.

        Without hooks the steps are taken in `rounds` batches with `between()` called
        between them (the contact proxies catch up within the frame). Groups never read
        each other's data while they step, so the result does not depend on the number
        of threads. Asleep or frozen groups keep their state; the clock moves on.
        """
        active = [g for g in self.groups if g.active]
        if before_substep is not None:
            for i in range(substeps):
                before_substep(i)
                self._run(active, 1)
        else:
            batches = [int(n) for n in np.diff(np.linspace(0, substeps, rounds + 1).round())]
            for k, n in enumerate(b for b in batches if b):
                if k and between is not None:
                    between()
                self._run(active, n)
        self.time += substeps * self.substep_dt

    def step_bare(self, datas: Sequence[mujoco.MjData], substeps: int) -> None:
        """Step `datas` (one per group, in group order) on this pool, with nothing else.

        For benchmarks: the framework's cost is a frame minus this.
        """
        self._map([Bare(g.model, d) for g, d in zip(self.groups, datas, strict=True)], substeps)

    def _run(self, groups: list[PhysicsGroup], substeps: int) -> None:
        for group, error in zip(groups, self._map(groups, substeps), strict=True):
            if error is not None:
                group.error = error

    def _map(self, groups: Sequence[Steppable], substeps: int) -> list[str | None]:
        """Step each of `groups` (anything with `model` and `data`); MuJoCo's fatal errors
        (a blown-up state overflowing its arena) come back per group instead of raising."""
        if self._pool is None or len(groups) < 2:
            return _step_chunk(groups, substeps)
        chunks = _balanced_chunks(groups, self.threads)
        futures = [self._pool.submit(_step_chunk, chunk, substeps) for chunk in chunks]
        return [error for future in futures for error in future.result()]

    def sync(self, transforms: TransformStore) -> None:
        """Copy every body's world pose into the Transform store (one gather per group)."""
        for group in self.groups:
            group.sync(transforms)

    # -- queries ---------------------------------------------------------------------
    @property
    def substep_dt(self) -> float:
        return float(self.groups[0].model.opt.timestep) if self.groups else 0.0

    def group_of(self, creature: Creature) -> PhysicsGroup:
        """The group that simulates `creature`."""
        return self.groups[int(self.group_of_creature_row[creature.row])]

    @property
    def bodies(self) -> int:
        """Creature bodies in all groups (proxies not counted)."""
        return int(sum(len(g.body_ids) for g in self.groups))

    @property
    def dofs(self) -> int:
        return int(sum(g.model.nv for g in self.groups))

    def close(self) -> None:
        """Stop the thread pool."""
        if self._pool is not None:
            self._pool.shutdown(wait=True)
            self._pool = None

    def __repr__(self) -> str:
        return (
            f"<physics: {len(self.groups)} groups, {self.compiles} compiled models,"
            f" {self.threads} threads>"
        )


class Steppable(Protocol):
    model: mujoco.MjModel
    data: mujoco.MjData


@dataclass
class Bare:
    """A model with a data of its own, stepped without the framework (benchmarks)."""

    model: mujoco.MjModel
    data: mujoco.MjData


def _step_chunk(groups: Sequence[Steppable], substeps: int) -> list[str | None]:
    errors: list[str | None] = []
    for group in groups:
        try:
            mujoco.mj_step(group.model, group.data, nstep=substeps)
            errors.append(None)
        except mujoco.FatalError as exc:
            errors.append(str(exc).splitlines()[0])
    return errors


def _balanced_chunks(groups: Sequence[Steppable], threads: int) -> list[Sequence[Steppable]]:
    """Split `groups` into at most `threads` contiguous runs of about equal dofs."""
    cost = np.cumsum([g.model.nv + 1 for g in groups], dtype=np.float64)
    cuts = np.searchsorted(cost, cost[-1] * np.arange(1, threads) / threads)
    bounds = [0, *cuts.tolist(), len(groups)]
    return [groups[a:b] for a, b in itertools.pairwise(bounds) if b > a]
