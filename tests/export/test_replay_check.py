"""A recorder's replay check in one pass (numba) decides as the take's own numpy
reconstruction does: replayed creature-frames within 1 mm and a tenth of a degree are
recorded as replay, the others keep their poses."""

from __future__ import annotations

import numpy as np
import pytest

from ecs_tentacles.export.replay_recording import ROTATION
from ecs_tentacles.take import replay as take_replay

kernel = pytest.importorskip("ecs_tentacles.export.replay_check_kernel")


def _clip(rng: np.random.Generator, frames: int, bodies: int) -> np.ndarray:
    pose = rng.normal(size=(frames, bodies, 7))
    pose[..., :3] *= 0.3
    pose[..., 3:] /= np.linalg.norm(pose[..., 3:], axis=-1, keepdims=True)
    return pose


def test_the_kernel_accepts_and_refuses_what_the_numpy_check_does() -> None:
    rng = np.random.default_rng(7)
    idle, crawl, bodies, k = 5, 9, 6, 40
    pose = _clip(rng, idle + crawl, bodies)
    kind = rng.integers(0, 2, size=k)
    phase = rng.uniform(-20.0, 40.0, size=k)
    xy, heading = rng.uniform(-30, 30, size=(k, 2)), rng.uniform(-7, 7, size=k)
    ground = take_replay.blend(pose, (idle, crawl), kind, phase)
    pos, quat = take_replay.place(ground, xy, heading)
    store = rng.permutation(k * bodies).reshape(k, bodies)  # the world's rows, shuffled
    world_pos = np.zeros((k * bodies, 3), np.float32)
    world_quat = np.zeros((k * bodies, 4), np.float32)
    world_pos[store], world_quat[store] = pos, quat
    world_quat[store[1:4]] *= -1.0  # the same rotations, the other sign
    world_pos[store[5, 3], 0] += 0.0009  # within 1 mm
    world_pos[store[6, 2], 2] -= 0.0011  # over it
    turned = np.array([np.cos(0.001), 0.0, 0.0, np.sin(0.001)])  # 0.11 degrees about z
    q = world_quat[store[7, 4]].astype(np.float64)
    world_quat[store[7, 4]] = [  # q turned by `turned`: 1 - |q . q'| is 5e-7 (kept)
        turned[0] * q[0] - turned[3] * q[3], turned[0] * q[1] - turned[3] * q[2],
        turned[0] * q[2] + turned[3] * q[1], turned[0] * q[3] + turned[3] * q[0],
    ]  # fmt: skip
    world_quat[store[8, 0]] = [0.0, 1.0, 0.0, 0.0]  # far off
    got = kernel.replay_within(pose, idle, crawl, kind, phase, xy, heading, store,
                               world_pos, world_quat, take_replay.TOLERANCE, ROTATION)  # fmt: skip
    near = np.abs(pos - world_pos[store]).max(axis=(1, 2)) <= take_replay.TOLERANCE
    dot = np.abs(np.einsum("kbi,kbi->kb", quat, world_quat[store]))
    numpy = near & ((1.0 - dot).max(axis=1) <= ROTATION)
    assert np.array_equal(got, numpy)
    assert not got[6] and not got[8] and got[5] and got[7] and got[1:4].all()
    assert got.sum() == k - 2
