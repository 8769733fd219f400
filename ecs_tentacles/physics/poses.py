"""A batch's body poses from its rows' joint angles: the reduced tier's show step.

A REDUCED row is stepped with the reduced model and shown as the full creature: its
full state's joint angles are expanded from the reduced ones (`physics.reduced`), and
the full model's body poses follow from them by forward kinematics. `PoseMap` reads
what that needs of the full model once (each body's parent, its place in the parent,
its joints) and `PoseMap.show` writes the poses of many rows into the batch's `xpos` /
`xquat`: in one call of the numba kernel (`physics.pose_kernels`: MuJoCo's arithmetic,
the same bits) for all rows, or, without numba or for bodies the kernel does not
cover (mocap, ball or slide joints), row by row with MuJoCo's `mj_kinematics` on a
scratch copy of the full model.
"""

from __future__ import annotations

import mujoco
import numpy as np

from ecs_tentacles.numeric.optional_kernels import OptionalKernels

# the show step's forward kinematics by numba when installed (`physics.pose_kernels`);
# =numpy: MuJoCo's mj_kinematics row by row
KERNELS = OptionalKernels("ecs_tentacles.physics.pose_kernels", "ECS_TENTACLES_POSES")


class PoseMap:
    """What forward kinematics of bodies `bodies` (ids of `model`, a creature's: parents
    before children) reads of the model, as arrays for the kernel; `covered` is False
    when a body needs more than free and hinge joints (MuJoCo then does the work)."""

    def __init__(self, model: mujoco.MjModel, bodies: np.ndarray) -> None:
        self.bodies = np.asarray(bodies, dtype=np.int64)
        at = {int(b): k for k, b in enumerate(self.bodies.tolist())}
        count = len(self.bodies)
        self.parent = np.full(count, -1, dtype=np.int64)
        self.free = np.zeros(count, dtype=np.bool_)
        self.body_pos = np.array(model.body_pos[self.bodies], dtype=np.float64)
        self.body_quat = np.array(model.body_quat[self.bodies], dtype=np.float64)
        self.joint_start = np.zeros(count + 1, dtype=np.int64)
        joints: list[int] = []
        covered = True
        hinge, free = int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_FREE)
        for k, b in enumerate(self.bodies.tolist()):
            own = list(range(model.body_jntadr[b], model.body_jntadr[b] + model.body_jntnum[b]))
            kinds = [int(model.jnt_type[j]) for j in own]
            parent = int(model.body_parentid[b])
            if kinds == [free]:
                self.free[k] = True
            elif any(kind != hinge for kind in kinds) or model.body_mocapid[b] >= 0:
                covered = False
            if parent and not self.free[k]:
                if parent not in at or at[parent] >= k:
                    covered = False
                self.parent[k] = at.get(parent, -1)
            joints += own
            self.joint_start[k + 1] = len(joints)
        ids = np.array(joints, dtype=np.int64)
        self.joint_qpos = np.array(model.jnt_qposadr[ids], dtype=np.int64)
        self.joint_axis = np.array(model.jnt_axis[ids], dtype=np.float64)
        self.joint_pos = np.array(model.jnt_pos[ids], dtype=np.float64)
        self.joint_qpos0 = np.array(model.qpos0[self.joint_qpos], dtype=np.float64)
        self.covered = covered

    def show(
        self,
        rows: np.ndarray,
        state: np.ndarray,
        qpos: slice,
        xpos: np.ndarray,
        xquat: np.ndarray,
        model: mujoco.MjModel,
        data: mujoco.MjData,
    ) -> None:
        """Rows `rows`' body poses from their joint angles (state[:, qpos], the full
        model's qpos) into xpos[rows] and xquat[rows] (rows, bodies, 3 / 4); `model` and
        `data` (a scratch copy of the full model and its data) when MuJoCo does it."""
        fast = KERNELS.get() if self.covered else None
        if fast is not None:
            fast.body_poses(rows, state, qpos.start, self.parent, self.free, self.body_pos,
                            self.body_quat, self.joint_start, self.joint_qpos, self.joint_axis,
                            self.joint_pos, self.joint_qpos0, xpos, xquat)  # fmt: skip
            return
        joints, poses, turns, bodies = data.qpos, data.xpos, data.xquat, self.bodies
        for row in rows.tolist():
            joints[:] = state[row, qpos]
            mujoco.mj_kinematics(model, data)
            xpos[row] = poses[bodies]
            xquat[row] = turns[bodies]
