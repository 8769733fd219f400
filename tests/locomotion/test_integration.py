"""Whole frames, every system: a creature crawls toward its goal; without one it writhes."""

from __future__ import annotations

from collections.abc import Callable

import mujoco
import numpy as np

from ecs_tentacles.components import Transform
from ecs_tentacles.locomotion.goals import GoalBook
from ecs_tentacles.locomotion.params import Locomotion
from ecs_tentacles.world import World
from tests.conftest import creature_scene


def test_coordinated_creature_crawls_toward_its_goal(make_world: Callable[..., World]) -> None:
    scene = creature_scene(count=4)
    scene["creatures"][0]["locomotion"] = {"gait": "coordinated"}
    scene["creatures"][0]["goals"] = [{"position": [1.5, 0.0]}]
    world = make_world(scene)
    octo = world.creature("octo")
    mantle = world.component(octo, Transform)
    goal = np.array([1.5, 0.0])
    start = float(np.linalg.norm(goal - mantle.pos[:2]))
    world.step(240)  # 4 simulated seconds
    data = world.physics.views[0].data
    assert np.isfinite(data.qpos).all() and np.isfinite(data.qvel).all()
    assert world.physics.health.recoveries == 0
    assert float(np.linalg.norm(goal - mantle.pos[:2])) < start - 0.15
    assert world.events.counts["sucker_attached"] >= 2  # it crawled with its suckers
    assert world.resource(GoalBook).path(octo) != []  # 1.5 m is too far for 4 s


def test_idle_creature_writhes_in_place(make_world: Callable[..., World]) -> None:
    world = make_world(creature_scene())  # 8 tentacles, no goal
    octo = world.creature("octo")
    mantle = world.component(octo, Transform)
    model, data = world.physics.views[0].model, world.physics.views[0].data
    hinges = np.flatnonzero(model.jnt_type == mujoco.mjtJoint.mjJNT_HINGE)
    assert len(hinges) == 8 * 10 * 2  # curl and sweep of every link
    start = mantle.pos[:2].copy()
    angles = []
    for _ in range(180):  # 3 simulated seconds
        world.step(1)
        angles.append(data.qpos[model.jnt_qposadr[hinges]].copy())
    assert float(np.linalg.norm(mantle.pos[:2] - start)) < 0.05
    assert np.array(angles).std(axis=0).min() > 0.01  # every joint moves
    assert world.resource(Locomotion).actions(octo) == ["idle"] * 8
    assert world.events.counts["sucker_attached"] == 0
