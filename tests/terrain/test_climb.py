"""Crawling up a slope: the octopus reaches a goal 2 m up a 15 degree ramp."""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from ecs_tentacles.ground import ground_of
from ecs_tentacles.world import World

SLOPE = 15.0
UP = 2.0  # metres along the slope


def test_a_goal_2_m_up_a_15_degree_ramp_is_reached(make_world: Callable[..., World]) -> None:
    rise = math.tan(math.radians(SLOPE))
    xs = np.linspace(-3.5, 3.5, 71)  # the samples along x; the ramp's foot at x = 0
    row = [round(rise * max(0.0, x), 5) for x in xs]
    goal_x = UP * math.cos(math.radians(SLOPE))
    scene = {
        "version": 1,
        "terrain": {"heightfield": {"size": [7.0, 3.0], "heights": [row] * 31}},
        "creatures": [
            {"name": "climber", "position": [0.1, 0], "goals": [{"position": [goal_x, 0]}]}
        ],
    }
    world = make_world(scene)
    ground = ground_of(world)
    assert ground.height(np.array([[goal_x, 0.0]]))[0] > 0.5  # the goal is 0.52 m up
    reached: list[float] = []
    world.events.on("goal_reached", lambda **_: reached.append(world.time))
    while world.time < 60.0 and not reached:
        world.step()
    assert reached, world.transforms.pos[world.creatures.mantle_row[0]]
    assert world.physics.health.recoveries == 0
