"""goals: the creatures that reach their goal are the same with and without the kernel."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

from ecs_tentacles.creator.crowd import crowd_scene
from ecs_tentacles.locomotion.stores import LocomotionStores
from ecs_tentacles.locomotion.systems import goals
from ecs_tentacles.world import World


def test_a_mantle_exactly_on_its_goals_radius_arrives_either_way(
    make_world: Callable[..., World], monkeypatch: pytest.MonkeyPatch
) -> None:
    assert goals.KERNELS.get() is not None  # numba comes with the dev extra
    world = make_world(crowd_scene(12, seed=3))
    world.step(5)
    system = next(s for s in world.schedule if isinstance(s, goals.Goals))
    start = world.snapshot()

    def place_goals() -> None:
        gaits = world.resource(LocomotionStores).creatures
        mantle = world.transforms.pos[world.creatures.mantle_row, :2]
        rng = np.random.default_rng(1)
        gaits.goal[:, :2] = mantle + rng.normal(0.0, 0.3, mantle.shape)
        offset = mantle - gaits.goal[:, :2]
        distance = np.sqrt(offset[:, 0] * offset[:, 0] + offset[:, 1] * offset[:, 1])
        # on the radius, one ulp inside it, one ulp short of it, far, and one with no goal
        gaits.goal_radius[:] = 0.01
        gaits.goal_radius[::4] = distance[::4]
        gaits.goal_radius[1::4] = np.nextafter(distance[1::4], np.inf)
        gaits.goal_radius[2::4] = np.nextafter(distance[2::4], 0.0)
        gaits.has_goal[5] = False

    arrived: list[list[Any]] = []
    world.events.on("goal_reached", lambda creature, **_: arrived[-1].append(creature))
    for backend in ("auto", "numpy"):
        monkeypatch.setattr(goals.KERNELS, "backend", backend)
        world.restore(start)
        place_goals()
        arrived.append([])
        system.process(world, world.settings.dt)
    assert arrived[0] == arrived[1]
    assert 2 <= len(arrived[0]) <= 8  # some on or just inside their radius, none past it
