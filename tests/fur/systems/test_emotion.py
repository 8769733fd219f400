"""Emotion: threats near raise fear with anticipation and slow-out, and drive the fur."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.testing import assert_allclose

from ecs_tentacles.fur import Emotion
from ecs_tentacles.fur.stores import FurData
from ecs_tentacles.fur.systems.emotion import NINETY_PERCENT
from ecs_tentacles.world import World
from tests.conftest import NO_LOCOMOTION

FAR, NEAR = [5.0, 0.0, 0.1], [0.5, 0.0, 0.1]


def scene(anticipation: float, **extra: Any) -> dict[str, Any]:
    """A hedgehog roused from t = 1 s (the threat jumps in) to t = 3 s (it jumps away)."""
    path = [
        {"time": 0, "position": FAR, "easing": "step"},
        {"time": 1, "position": NEAR, "easing": "step"},
        {"time": 3, "position": FAR},
    ]
    hedgehog = {
        "name": "hog",
        "tentacles": {"count": 3, "links": 2},
        "fur": {"preset": "hedgehog", "groom": {"count": 30}},
        "emotion": {"radius": 1.0, "rise_s": 0.5, "decay_s": 1.0, "anticipation": anticipation},
    }
    return {"version": 1, "creatures": [hedgehog], "threats": [{"path": path}]} | extra


def levels(world: World, frames: int) -> np.ndarray:
    out = []
    for _ in range(frames):
        world.step(1)
        out.append(world.resource(FurData).emotions.level[0])
    return np.array(out)


def test_level_follows_a_critically_damped_rise(make_world: Callable[..., World]) -> None:
    world = make_world(scene(0.0), plugins=NO_LOCOMOTION)
    level = levels(world, 120)
    assert np.all(level[:60] == 0.0)  # frames at t < 1: calm
    t = (np.arange(60, 120) - 59) / 60.0  # seconds of arousal after each of those frames
    omega = NINETY_PERCENT / 0.5
    assert_allclose(level[60:], 1 - (1 + omega * t) * np.exp(-omega * t), atol=1e-12)
    assert abs(level[89] - 0.9) < 0.01  # 90 % after rise_s


def test_anticipation_then_slow_out_and_decay(make_world: Callable[..., World]) -> None:
    world = make_world(scene(0.4), plugins=NO_LOCOMOTION)
    level = levels(world, 6 * 60)
    emotion = world.component(world.creature("hog"), Emotion)
    assert emotion.kind == "fear" and not emotion.threatened
    onset = level[60:70]
    assert onset.min() < -0.02 and np.argmin(onset) > 0  # dips first (anticipation)
    assert level[60 + 60] > 0.95  # then bristles
    assert level[179] > 0.99
    leave = level[180:]
    assert leave[:5].max() > level[179]  # swells a little before it falls
    assert leave[0] - level[179] < 0.01  # and leaves the pose slowly
    assert leave[-1] < 0.1 and leave[-1] > 0.0


def test_emotion_drives_the_controls(make_world: Callable[..., World]) -> None:
    world = make_world(scene(0.3), plugins=NO_LOCOMOTION)
    world.step(100)
    level = world.resource(FurData).emotions.level[0]
    c, sets = world.resource(FurData).controls, world.resource(FurData).sets
    assert level > 0.5
    assert_allclose(c.drive_lift, level * sets.erect_lift[0] * c.emotion)
    assert_allclose(c.drive_random, level * sets.erect_random[0] * c.emotion)
    g = world.resource(FurData).guides
    up = np.sum(
        world.resource(FurData).frames[:, 0] * world.resource(FurData).frames[:, 1], axis=1
    )  # sanity: orthogonal
    assert_allclose(up, 0.0, atol=1e-6)
    elevation = np.einsum("ij,ij->i", g.rest, g.normal)
    assert elevation.max() < 0.2  # quills rest flat ...
    # ... and stand up: the rig's result is lifted toward each normal
    from ecs_tentacles.numeric.quaternions import quat_rotate

    normals = quat_rotate(world.transforms.quat[g.body_row], g.normal)
    raised = np.sum(world.resource(FurData).frames[:, 0] * normals, axis=1)
    assert raised.min() > 0.5


def test_a_creature_marked_threat_frightens_others_not_itself(
    make_world: Callable[..., World],
) -> None:
    tentacles = {"count": 3, "links": 2}
    data = {
        "version": 1,
        "creatures": [
            {"name": "prey", "tentacles": tentacles, "emotion": {"radius": 1.0}},
            {
                "name": "wolf",
                "position": [0.6, 0],
                "tentacles": tentacles,
                "threat": True,
                "emotion": {"radius": 1.0},
            },
            {"name": "far", "position": [5, 0], "tentacles": tentacles, "emotion": {}},
        ],
    }
    world = make_world(data, plugins=NO_LOCOMOTION)
    world.step(30)
    e = world.resource(FurData).emotions
    assert list(e.threatened) == [True, False, False]
    assert e.level[0] > 0.5 and e.level[1] == 0.0 and e.level[2] == 0.0
