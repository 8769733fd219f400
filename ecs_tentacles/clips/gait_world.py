"""A gait recorded from one creature with the full physics: a one-creature world, stepped
frame by frame (the clips' source; not a take: takes are the `record` plugin's).

`one_creature_scene` turns a scene creature entry (a `load_scene(...)["creatures"][i]`
or a `crowd_scene` entry) into a scene holding that creature alone at the origin,
heading 0, crawling to a goal straight ahead (or with no goal: idle). `simulate` builds
that world (`World.from_scene`), steps it, and returns every frame's MuJoCo joint
state (`_joint_state`, the one place that reads the backend's data) and the body
poses forward kinematics gives for it (mantle first, then each tentacle's links, the
order of `model_layout(...).bodies`). Poses come from the recorded qpos, not from the
Transform store, so a clip's poses and joint state agree exactly (the store lags the
state by one substep: `GaitRecording.store_lag` says by how much).
"""

from __future__ import annotations

import copy
import time
from dataclasses import dataclass

import mujoco
import numpy as np

from ecs_tentacles.components import Creature, Transform
from ecs_tentacles.physics.model import build_spec, model_layout
from ecs_tentacles.scene.scene_spec import PhysicsSpec
from ecs_tentacles.world import World

GOAL_RADIUS = 0.3
# Keys of a creature entry that the recording leaves out: they do not move the body.
NOT_RECORDED = ("fur",)
# Keys of the scene's `physics` it leaves out: `simulate` runs the creature alone at full
# physics (`lod=False`), so the level of detail's budgets, hold and focus never move it,
# and scenes that differ only there replay one recording (in a process and on disk).
NOT_RECORDED_PHYSICS = ("lod",)


@dataclass
class GaitRecording:
    """Frames of one creature's full simulation; shapes (F, ...), world frame."""

    key: tuple[object, ...]  # the physics morphology key (`model_layout(...).key`)
    model: mujoco.MjModel  # the creature's compiled model (for forward kinematics)
    dt: float  # seconds per frame
    bodies: list[str]  # body names, mantle first
    pos: np.ndarray  # (F, B, 3)
    quat: np.ndarray  # (F, B, 4) wxyz
    qpos: np.ndarray  # (F, nq), the free joint first
    qvel: np.ndarray  # (F, nv)
    store_lag: float  # largest distance (m) between a stored pose and its qpos's pose
    seconds: float  # wall-clock cost of building and stepping the world


def one_creature_scene(
    creature: dict[str, object], physics: PhysicsSpec | None = None, goal: float | None = None
) -> dict[str, object]:
    """A scene of `creature` alone at the origin, heading 0, its goal `goal` m ahead (None: idle).

    `physics` is the scene's `physics` object (None: the defaults) less its level of
    detail (`NOT_RECORDED_PHYSICS`: a recording steps the creature at full physics
    whatever the scene's budgets). Plugins come from the scene's defaults; the scene's
    own systems and threats are left out.
    """
    entry = {k: copy.deepcopy(v) for k, v in creature.items() if k not in NOT_RECORDED}
    entry.update(position=[0.0, 0.0], heading_deg=0.0)
    entry["goals"] = [] if goal is None else [{"position": [goal, 0.0], "radius": GOAL_RADIUS}]
    scene: dict[str, object] = {"version": 1, "name": "clip", "creatures": [entry]}
    if physics is not None:
        scene["physics"] = {
            k: copy.deepcopy(v) for k, v in physics.items() if k not in NOT_RECORDED_PHYSICS
        }
    return scene


def simulate(scene: dict[str, object], warmup: float, seconds: float) -> GaitRecording:
    """Build `scene` (one creature), step `warmup` s, then keep `seconds` s frame by frame."""
    start = time.perf_counter()
    world = World.from_scene(scene, threads=1, lod=False)  # full physics, whatever the scene says
    try:
        _, (creature, transform) = next(iter(world.query(Creature, Transform)))
        layout = model_layout(world, creature, transform)
        world.step(round(warmup / world.settings.dt))
        frames = max(2, round(seconds / world.settings.dt))
        rows = np.asarray(layout.body_rows)
        qpos, qvel, stored = [], [], []
        for _ in range(frames):
            world.step()
            q, v = _joint_state(world)
            qpos.append(q.copy())
            qvel.append(v.copy())
            stored.append(world.transforms.pos[rows].copy())
        model = build_spec(world, creature).compile()
        dt = world.settings.dt
    finally:
        world.close()
    qpos_all = np.array(qpos)
    pos, quat = forward_poses(model, layout.bodies, qpos_all)
    lag = float(np.linalg.norm(pos - np.array(stored), axis=-1).max())
    return GaitRecording(
        layout.key, model, dt, list(layout.bodies), pos, quat, qpos_all, np.array(qvel), lag,
        time.perf_counter() - start,
    )  # fmt: skip


def _joint_state(world: World) -> tuple[np.ndarray, np.ndarray]:
    """The one creature's MuJoCo qpos and qvel (views; copy before stepping on)."""
    data = world.physics.views[0].data
    return data.qpos, data.qvel


def forward_poses(
    model: mujoco.MjModel, bodies: list[str], qpos: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """World poses (F, B, 3) / (F, B, 4) of `bodies` for every row of `qpos` (F, nq)."""
    data = mujoco.MjData(model)
    ids = np.array([mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, b) for b in bodies])
    pos = np.empty((len(qpos), len(ids), 3))
    quat = np.empty((len(qpos), len(ids), 4))
    for f, q in enumerate(qpos):
        data.qpos[:] = q
        mujoco.mj_kinematics(model, data)
        pos[f] = data.xpos[ids]
        quat[f] = data.xquat[ids]
    return pos, quat
