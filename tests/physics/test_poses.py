"""The reduced tier's show step (`physics.poses`): body poses from joint angles, MuJoCo's
`mj_kinematics` bit for bit, and a crowd's reduced frames the same bits through the
kernel as through MuJoCo row by row (the path it replaced)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import mujoco
import numpy as np
import pytest

from ecs_tentacles.physics import poses as poses_module
from ecs_tentacles.physics.poses import PoseMap
from ecs_tentacles.physics.state_layout import S
from ecs_tentacles.physics.tiers import REDUCED
from ecs_tentacles.world import World


def _crowd(twist: bool) -> dict[str, Any]:
    """Six creatures of two body plans (one with twist hinges), all at the reduced tier."""
    creatures = []
    for i in range(6):
        tentacles = {"count": 3 + i % 2 * 2, "links": 6 + i % 2 * 4, "twist": twist and i % 2 == 1}
        x, y = 3.0 * (i % 3), 3.0 * (i // 3)
        goals = [{"position": [x + 3.0, y + 1.0]}]
        creatures.append({"name": f"c{i}", "position": [x, y], "tentacles": tentacles,
                          "goals": goals})  # fmt: skip
    return {"version": 1, "physics": {"lod": {"full": 0, "reduced": 8}}, "creatures": creatures}


def _mujocos_poses(
    model: mujoco.MjModel, bodies: np.ndarray, states: np.ndarray, qpos: slice
) -> tuple[np.ndarray, np.ndarray]:
    data = mujoco.MjData(model)
    xpos, xquat = np.zeros((len(states), len(bodies), 3)), np.zeros((len(states), len(bodies), 4))
    for row, state in enumerate(states):
        data.qpos[:] = state[qpos]
        mujoco.mj_kinematics(model, data)
        xpos[row], xquat[row] = data.xpos[bodies], data.xquat[bodies]
    return xpos, xquat


@pytest.mark.parametrize("twist", [False, True])
def test_the_kernels_poses_are_mujocos_bit_for_bit(
    make_world: Callable[..., World], twist: bool
) -> None:
    assert poses_module.KERNELS.get() is not None  # numba comes with the dev extra
    world = make_world(_crowd(twist))
    world.step(20)
    rng = np.random.default_rng(0)
    for batch in world.physics.batches:
        qpos = batch.slices[int(S.mjSTATE_QPOS)]
        states = np.repeat(batch.state, 40, axis=0)  # the states reached, bent every way
        joints = slice(qpos.start + 7, qpos.stop)
        states[len(batch) :, joints] += rng.normal(0.0, 0.8, (len(states) - len(batch), 1))
        states[len(batch) :, joints] *= rng.uniform(0.0, 2.0, states[len(batch) :, joints].shape)
        states[1::7, joints] = 0.0  # unbent: MuJoCo's own branches for a zero angle
        states[2::7, joints] = -0.0
        states[3::7, qpos.start + 3 : qpos.start + 7] = [1.0, 0.0, 0.0, 0.0]  # level mantle
        states[4::7, qpos.start + 3 : qpos.start + 7] *= 1.0 + 1e-7  # quaternion to normalise
        pose_map = PoseMap(batch.model, batch.body_ids)
        assert pose_map.covered
        rows = np.arange(len(states))
        xpos = np.zeros((len(rows), len(batch.body_ids), 3))
        xquat = np.zeros((len(rows), len(batch.body_ids), 4))
        pose_map.show(rows, states, qpos, xpos, xquat, batch.model, mujoco.MjData(batch.model))
        expected = _mujocos_poses(batch.model, batch.body_ids, states, qpos)
        assert xpos.tobytes() == expected[0].tobytes()  # bits: signed zeros included
        assert xquat.tobytes() == expected[1].tobytes()


def test_only_some_rows_are_written(make_world: Callable[..., World]) -> None:
    world = make_world(_crowd(False))
    batch = world.physics.batches[0]
    qpos = batch.slices[int(S.mjSTATE_QPOS)]
    xpos, xquat = np.full_like(batch.xpos, 7.0), np.full_like(batch.xquat, 7.0)
    rows = np.array([2, 0])
    PoseMap(batch.model, batch.body_ids).show(
        rows, batch.state, qpos, xpos, xquat, batch.model, mujoco.MjData(batch.model)
    )
    expected = _mujocos_poses(batch.model, batch.body_ids, batch.state[rows], qpos)
    np.testing.assert_array_equal(xpos[rows], expected[0])
    np.testing.assert_array_equal(xquat[rows], expected[1])
    assert (xpos[1] == 7.0).all() and (xquat[1] == 7.0).all()


def test_bodies_past_free_and_hinge_joints_are_left_to_mujoco() -> None:
    """A slide joint, a ball joint or a mocap body: the kernel does not cover the model, and
    MuJoCo's poses come out all the same."""
    model = mujoco.MjModel.from_xml_string(
        """<mujoco><worldbody>
        <body name="a" pos="0 0 1"><freejoint/><geom size=".1"/>
          <body name="b" pos=".2 0 0"><joint type="slide" axis="1 0 0"/><geom size=".1"/>
            <body name="c" pos=".2 0 0"><joint type="ball"/><geom size=".1"/></body>
          </body>
        </body>
        <body name="m" mocap="true" pos="1 1 1"><geom size=".1" contype="0"/></body>
        </worldbody></mujoco>"""
    )
    bodies = np.array([1, 2, 3])
    assert not PoseMap(model, bodies).covered
    assert not PoseMap(model, np.array([4])).covered  # the mocap body
    states = np.random.default_rng(1).normal(0.0, 0.5, (3, model.nq))
    qpos = slice(0, model.nq)
    xpos, xquat = np.zeros((3, 3, 3)), np.zeros((3, 3, 4))
    PoseMap(model, bodies).show(np.arange(3), states, qpos, xpos, xquat, model,
                                mujoco.MjData(model))  # fmt: skip
    expected = _mujocos_poses(model, bodies, states, qpos)
    np.testing.assert_array_equal(xpos, expected[0])
    np.testing.assert_array_equal(xquat, expected[1])


def test_a_reduced_crowd_steps_the_same_bits_with_the_kernel_as_with_mujoco(
    make_world: Callable[..., World], monkeypatch: pytest.MonkeyPatch
) -> None:
    """The show step's kernel replaced MuJoCo's `mj_kinematics` row by row: the same
    frames, bit for bit, poses and states."""
    runs = []
    for backend in ("auto", "numpy"):
        monkeypatch.setattr(poses_module.KERNELS, "backend", backend)
        world = make_world(_crowd(True), threads=2)
        world.step(40)
        assert world.lod.counts()["reduced"] == 6
        runs.append(world)
    kernel, mujocos = runs
    assert kernel.transforms.pos.tobytes() == mujocos.transforms.pos.tobytes()
    assert kernel.transforms.quat.tobytes() == mujocos.transforms.quat.tobytes()
    for ours, theirs in zip(kernel.physics.batches, mujocos.physics.batches, strict=True):
        assert ours.state.tobytes() == theirs.state.tobytes()
        assert ours.rstate.tobytes() == theirs.rstate.tobytes()
    moved = kernel.transforms.pos[kernel.physics.batches[0].body_rows[:, 0]]
    assert np.ptp(moved[:, 0]) > 0.0 and (kernel.physics.tier == REDUCED).all()


def test_a_state_gone_bad_gives_nan_and_infinite_poses_where_mujoco_does(
    make_world: Callable[..., World],
) -> None:
    """A blown-up row (NaN or infinite joints or root, before the health check restores
    it) is shown as MuJoCo shows it: the same values, a NaN's sign bit aside."""
    world = make_world(_crowd(True))
    for batch in world.physics.batches:
        qpos = batch.slices[int(S.mjSTATE_QPOS)]
        states = np.repeat(batch.state, 4, axis=0)
        states[0, qpos.start + 9] = np.nan  # a joint
        states[1, qpos.start + 3] = np.nan  # the mantle's orientation
        states[2, qpos.start] = np.inf  # its position
        states[3, qpos.start + 8] = -np.inf
        rows = np.arange(len(states))
        xpos = np.zeros((len(rows), len(batch.body_ids), 3))
        xquat = np.zeros((len(rows), len(batch.body_ids), 4))
        PoseMap(batch.model, batch.body_ids).show(
            rows, states, qpos, xpos, xquat, batch.model, mujoco.MjData(batch.model)
        )
        expected = _mujocos_poses(batch.model, batch.body_ids, states, qpos)
        np.testing.assert_array_equal(xpos, expected[0])  # NaN where MuJoCo's is NaN
        np.testing.assert_array_equal(xquat, expected[1])
        assert np.isnan(xpos[:2]).any() and not np.isfinite(xpos[2:]).all()
