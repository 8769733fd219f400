"""A physics group: one creature's compiled MuJoCo model and data, with its store rows.

Built from a compiled template (shared by every creature of the same morphology) and
placed by the free joint, so a creature alone in its group moves exactly as it would
in a one-creature world. Index arrays map the group's MuJoCo ids to the world's store
rows; the backend scatters controls through them and gathers poses back.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass
from typing import TYPE_CHECKING

import mujoco
import numpy as np

from ecs_tentacles.physics.model import PROXY_CAPSULES, PROXY_CYLINDERS, PROXY_PARK, ModelLayout

if TYPE_CHECKING:
    from ecs_tentacles.store import TransformStore

STATE = mujoco.mjtState.mjSTATE_INTEGRATION  # everything mj_step reads, warm start included


@dataclass(frozen=True)
class GroupState:
    """A group between frames: its MuJoCo integration state and its run-time flags."""

    integration: np.ndarray  # `PhysicsGroup.integration_state()`
    frozen: bool
    sleeping: bool
    soften: float


def _ids(model: mujoco.MjModel, kind: mujoco.mjtObj, names: list[str]) -> np.ndarray:
    return np.array([mujoco.mj_name2id(model, kind, n) for n in names], dtype=np.int64)


class PhysicsGroup:
    """One creature's `model` and `data`; `creatures` lists the creature entities in it."""

    def __init__(
        self,
        index: int,
        creature: int,
        creature_row: int,
        layout: ModelLayout,
        template: mujoco.MjModel,
        pose: tuple[np.ndarray, np.ndarray],
    ):
        self.index = index
        self.creatures = [creature]
        self.creature_row = creature_row
        self.key = layout.key
        self.model = copy.copy(template)  # own copy: gains and anchors are written per frame
        self.data = mujoco.MjData(self.model)
        m, obj = self.model, mujoco.mjtObj
        self.body_ids = _ids(m, obj.mjOBJ_BODY, layout.bodies)
        self.body_rows = np.asarray(layout.body_rows, dtype=np.int64)
        actuators = _ids(m, obj.mjOBJ_ACTUATOR, layout.actuators)
        order = np.argsort(actuators)
        self.actuator_motor_rows = np.asarray(layout.actuator_motor_rows, dtype=np.int64)[order]
        axes = np.asarray(layout.actuator_axes, dtype=np.int64)[order]
        self.actuator_target_index = self.actuator_motor_rows * 3 + axes
        self.equality_ids = _ids(m, obj.mjOBJ_EQUALITY, layout.equalities)
        self.sucker_rows = np.asarray(layout.sucker_rows, dtype=np.int64)
        self.root_qpos = int(m.jnt_qposadr[m.joint("root").id])
        proxies = [f"proxy/capsule{i}" for i in range(PROXY_CAPSULES)]
        proxies += [f"proxy/cylinder{i}" for i in range(PROXY_CYLINDERS)]
        self.proxy_geoms = _ids(m, obj.mjOBJ_GEOM, proxies)
        self.proxy_mocap = m.body_mocapid[_ids(m, obj.mjOBJ_BODY, proxies)]
        self.proxy_park = PROXY_PARK + np.outer(np.arange(len(proxies)) * 10.0, [1.0, 0.0, 0.0])
        self.proxies_used = 0  # proxies placed last frame (the rest are parked)
        # run-time state the backend and the health check keep
        self.frozen = False
        self.sleeping = False
        self.error: str | None = None  # MuJoCo's fatal error in the last step, if any
        self.soften = 1.0  # servo gain multiplier while recovering (1 = normal)
        self.warnings = np.zeros(len(self.data.warning.number), dtype=np.int64)
        self.warning_total = 0
        self.place(*pose)

    def place(self, pos: np.ndarray, quat: np.ndarray) -> None:
        """Put the creature's mantle at `pos` / `quat` with every joint at rest."""
        d = self.data
        mujoco.mj_resetData(self.model, d)
        d.qpos[self.root_qpos : self.root_qpos + 3] = pos
        d.qpos[self.root_qpos + 3 : self.root_qpos + 7] = quat
        d.mocap_pos[self.proxy_mocap] = self.proxy_park
        mujoco.mj_forward(self.model, d)

    # -- state ---------------------------------------------------------------------
    def integration_state(self) -> np.ndarray:
        """The data's integration state (qpos, qvel, warm start, ctrl, eq_active, ...)."""
        state = np.empty(mujoco.mj_stateSize(self.model, STATE))
        mujoco.mj_getState(self.model, self.data, state, STATE)
        return state

    def set_integration_state(self, state: np.ndarray, *, forward: bool = True) -> None:
        """Restore `integration_state()` output; `forward` recomputes poses from it.

        Without `forward` the derived arrays (poses, contacts) keep what they held:
        the next `mj_step` recomputes them from the state alone.
        """
        mujoco.mj_setState(self.model, self.data, state, STATE)
        if forward:
            mujoco.mj_forward(self.model, self.data)

    def state(self) -> GroupState:
        """A copy of everything that decides how this group steps on (for snapshots)."""
        return GroupState(self.integration_state(), self.frozen, self.sleeping, self.soften)

    def set_state(self, state: GroupState) -> None:
        """Go back to `state()`: bit-identical stepping from there.

        Poses are not recomputed (the Transform store holds them; the next step
        recomputes the data's). The warning counters restart from the data's and a
        pending fatal error is dropped: neither is state.
        """
        self.set_integration_state(state.integration, forward=False)
        self.frozen, self.sleeping, self.soften = state.frozen, state.sleeping, state.soften
        self.warnings[:] = self.data.warning.number
        self.error = None

    def sync(self, transforms: TransformStore) -> None:
        """Copy this group's body poses into the Transform store."""
        transforms.pos[self.body_rows] = self.data.xpos[self.body_ids]
        transforms.quat[self.body_rows] = self.data.xquat[self.body_ids]

    @property
    def active(self) -> bool:
        """Stepped this frame (not frozen after repeated failures, not asleep)."""
        return not (self.frozen or self.sleeping)

    def __repr__(self) -> str:
        m = self.model
        state = "frozen" if self.frozen else "asleep" if self.sleeping else "active"
        bodies = len(self.body_ids)
        return f"<physics group {self.index}: {bodies} bodies, {m.nv} dofs, {state}>"
