"""The compiled MuJoCo model and data, with index arrays from store rows to ids.

Built once per scene (`PhysicsBackend(world)`); per frame only array copies run:
`write_controls` (motor targets and gains), `write_suckers` (equality switches and
anchors), `step` (`mj_step` x substeps) and `sync` (body poses -> Transform store).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

import mujoco
import numpy as np

from ecs_tentacles.physics.model import build_spec

if TYPE_CHECKING:
    from ecs_tentacles.store import MotorStore, SuckerStore, TransformStore
    from ecs_tentacles.world import World


def _ids(model: mujoco.MjModel, kind: mujoco.mjtObj, names: list[str]) -> np.ndarray:
    return np.array([mujoco.mj_name2id(model, kind, n) for n in names], dtype=np.int64)


class PhysicsBackend:
    """MuJoCo model + data for a world, with entity-row -> MuJoCo-id maps."""

    def __init__(self, world: World):
        self.spec, names = build_spec(world)
        self.model = self.spec.compile()
        self.data = mujoco.MjData(self.model)
        obj = mujoco.mjtObj
        # transform row -> body id
        self.body_ids = _ids(self.model, obj.mjOBJ_BODY, names.bodies)
        # actuator i drives motor row actuator_motor_rows[i], hinge actuator_axes[i]
        actuator_ids = _ids(self.model, obj.mjOBJ_ACTUATOR, names.actuators)
        order = np.argsort(actuator_ids)
        self.actuator_motor_rows = np.asarray(names.actuator_motor_rows, dtype=np.int64)[order]
        self.actuator_target_index = (
            self.actuator_motor_rows * 3 + np.asarray(names.actuator_axes, dtype=np.int64)[order]
        )
        self.actuator_dof = self.model.jnt_dofadr[self.model.actuator_trnid[:, 0]]
        # sucker row -> equality id
        self.equality_ids = _ids(self.model, obj.mjOBJ_EQUALITY, names.equalities)
        self.mantle_qpos = self.model.jnt_qposadr[
            _ids(self.model, obj.mjOBJ_JOINT, names.mantle_joints)
        ]
        self.resets = 0
        mujoco.mj_forward(self.model, self.data)

    # -- per frame -------------------------------------------------------------------
    def write_controls(self, motors: MotorStore) -> None:
        """Targets into `ctrl`; kp = strength x gain, kv = damping x gain; torque limits."""
        m, d = self.model, self.data
        np.take(motors.target.reshape(-1), self.actuator_target_index, out=d.ctrl, mode="clip")
        rows = self.actuator_motor_rows
        gain = motors.gain[rows]
        kp = motors.strength[rows] * gain
        m.actuator_gainprm[:, 0] = kp
        m.actuator_biasprm[:, 1] = -kp
        m.actuator_biasprm[:, 2] = -motors.damping[rows] * gain
        torque = motors.max_torque[rows]
        m.actuator_forcerange[:, 0] = -torque
        m.actuator_forcerange[:, 1] = torque

    def write_suckers(self, suckers: SuckerStore) -> None:
        """Switch sucker equalities on/off and place their world anchors."""
        if not len(self.equality_ids):
            return
        self.model.eq_data[self.equality_ids, 3:6] = suckers.anchor
        self.data.eq_active[self.equality_ids] = suckers.attached

    def step(self, substeps: int, before_substep: Callable[[int], None] | None = None) -> None:
        """Advance `substeps` physics steps, calling `before_substep(i)` first if given."""
        m, d = self.model, self.data
        bad = mujoco.mjtWarning.mjWARN_BADQACC
        warnings_before = d.warning[bad].number
        if before_substep is None:
            mujoco.mj_step(m, d, nstep=substeps)
        else:
            for i in range(substeps):
                before_substep(i)
                mujoco.mj_step(m, d)
        self.resets += d.warning[bad].number - warnings_before

    def sync(self, transforms: TransformStore) -> None:
        """Copy every body's world pose into the Transform store (one gather per field)."""
        np.take(self.data.xpos, self.body_ids, axis=0, out=transforms.pos, mode="clip")
        np.take(self.data.xquat, self.body_ids, axis=0, out=transforms.quat, mode="clip")

    # -- queries ---------------------------------------------------------------------
    @property
    def time(self) -> float:
        return float(self.data.time)
