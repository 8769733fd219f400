"""What a creature's row of MuJoCo state holds (`STATE`, `state_slices`), what a batch
keeps per row beside it (`Rows`) and what of it is written into a model per row
(`write_overlay`, `size_proxies`): shared by the full and the reduced models' batches
(`physics.batch`, `physics.reduced`) and the bare replay (`physics.bare`)."""

from __future__ import annotations

from typing import Protocol

import mujoco
import numpy as np

S = mujoco.mjtState
# Everything `mj_step` reads that this project changes: the physics (time, qpos, qvel,
# act), the warm start (replays diverge without it), the servo targets, the sucker
# switches and the proxies' poses. Applied forces are not state here (`applied`).
STATE = (
    S.mjSTATE_FULLPHYSICS
    | S.mjSTATE_WARMSTART
    | S.mjSTATE_CTRL
    | S.mjSTATE_EQ_ACTIVE
    | S.mjSTATE_MOCAP_POS
    | S.mjSTATE_MOCAP_QUAT
)


def state_slices(model: mujoco.MjModel) -> dict[int, slice]:
    """Where each part of `STATE` (by its mjtState bit) lies in a state vector."""
    slices: dict[int, slice] = {}
    start = 0
    for bit in range(int(S.mjSTATE_INTEGRATION).bit_length()):
        flag = 1 << bit
        if int(STATE) & flag:
            size = mujoco.mj_stateSize(model, flag)
            slices[flag] = slice(start, start + size)
            start += size
    return slices


def size_proxies(
    m: mujoco.MjModel, geoms: np.ndarray, cylinder: np.ndarray, size: np.ndarray
) -> None:
    """Proxy geoms sized `size` (radius, half length) with matching bounds."""
    radius, half = size[:, 0], size[:, 1]
    m.geom_size[geoms, :2] = size
    m.geom_rbound[geoms] = np.where(cylinder, np.hypot(radius, half), radius + half)
    aabb = np.zeros((len(geoms), 6))
    aabb[:, 3:5] = radius[:, None]
    aabb[:, 5] = np.where(cylinder, half, half + radius)
    m.geom_aabb[geoms] = aabb


class Rows(Protocol):
    """What the model overlays read of a batch's rows (`physics.batch.Batch`, the bare
    replay's recorded rows)."""

    kp: np.ndarray
    kv: np.ndarray
    torque: np.ndarray
    anchor: np.ndarray
    near: np.ndarray
    proxy_size: np.ndarray
    proxy_cylinder: np.ndarray
    proxy_geoms: np.ndarray
    equality_ids: np.ndarray


def write_overlay(batch: Rows, m: mujoco.MjModel, row: int) -> None:
    """Row `row`'s servo gains, torque limits, sucker anchors and proxy sizes into `m`."""
    kp, torque = batch.kp[row], batch.torque[row]
    m.actuator_gainprm[:, 0] = kp
    m.actuator_biasprm[:, 1] = -kp
    m.actuator_biasprm[:, 2] = -batch.kv[row]
    m.actuator_forcerange[:, 0] = -torque
    m.actuator_forcerange[:, 1] = torque
    if len(batch.equality_ids):
        m.eq_data[batch.equality_ids, 3:6] = batch.anchor[row]
    if batch.near[row]:
        size_proxies(m, batch.proxy_geoms, batch.proxy_cylinder, batch.proxy_size[row])
