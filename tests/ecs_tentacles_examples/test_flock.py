"""The flock example plugin on its bundled scene: the crowd travels together, kept apart."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from ecs_tentacles.scene.errors import SceneError
from ecs_tentacles.world import World
from ecs_tentacles_examples.flock import Flock

SECONDS = 10
SEPARATION = 0.9  # metres: two mantles of the flock never come closer (tentacles reach 0.6)


def _fly(**config: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Every half second: the closest two mantles, the centroid, the farthest from it."""
    closest, centroid, spread = [], [], []
    plugins = {"flock": {"toward": [4.0, 0.0], **config}}
    with World.from_scene("flock", plugins=plugins) as world:
        for frame in range(0, SECONDS * 60 + 1, 30):
            if frame:
                world.step(30)
            mantles = world.transforms.pos[world.creatures.mantle_row, :2]
            gaps = np.linalg.norm(mantles[:, None] - mantles[None], axis=2)
            closest.append(gaps[np.triu_indices(len(mantles), 1)].min())
            centroid.append(mantles.mean(axis=0))
            spread.append(np.linalg.norm(mantles - centroid[-1], axis=1).max())
    return np.array(closest), np.array(centroid), np.array(spread)


def test_the_flock_travels_together_and_keeps_apart() -> None:
    closest, centroid, spread = _fly()
    assert closest.min() > SEPARATION, closest
    travelled = centroid[-1] - centroid[0]
    assert travelled[0] > 0.6 and abs(travelled[1]) < 0.2, travelled  # toward [4, 0]
    assert spread.max() <= spread[0] + 0.05, spread  # together: the spread never grows


def test_each_rule_steers_the_way_reynolds_says() -> None:
    with World.from_scene("flock") as world:  # its config, defaults filled
        flock = next(s for s in world.schedule if isinstance(s, Flock))
    pos = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 2.0], [20.0, 0.0]])  # the last is alone
    vel = np.array([[0.0, 0.0], [0.0, 0.1], [0.0, 0.1], [0.1, 0.0]])
    separate, align, cohere, seek = flock.steering(pos, vel)
    # 0 and 1 are 1 m apart (< separation 1.4): pushed apart by 1.4 / 1 - 1
    np.testing.assert_allclose(separate[:2], [[-0.4, 0.0], [0.4, 0.0]])
    np.testing.assert_allclose(separate[2:], 0.0)  # 2 is 2 m from both
    np.testing.assert_allclose(align[0], [0.0, 1.0])  # its neighbours crawl along +y at 0.1 m/s
    np.testing.assert_allclose(cohere[0], np.array([0.5, 1.0]) / 3.0)  # (centre - pos) / radius
    np.testing.assert_allclose([align[3], cohere[3], separate[3]], 0.0)  # no neighbours
    np.testing.assert_allclose(seek[3], [-1.0, 0.0])  # toward [4, 0]


def test_a_step_inside_the_goal_radius_is_refused() -> None:
    with pytest.raises(SceneError, match=r"plugins\.flock\.step: must be > goal_radius \(0\.5\)"):
        World.from_scene("flock", plugins={"flock": {"step": 0.45, "goal_radius": 0.5}})
