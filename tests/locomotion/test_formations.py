"""Formation goals: spaced by reach, every shape, obstacles avoided, nearest slots."""

from __future__ import annotations

import numpy as np
import pytest

from ecs_tentacles.locomotion.formations import SHAPES, formation_goals, reach, slots
from ecs_tentacles.world import World


def _world(count: int, terrain: dict | None = None) -> World:
    creatures = [
        {"name": f"c{i}", "position": [2.5 * (i % 5), 2.5 * (i // 5)],
         "tentacles": {"count": 4 + i % 3, "links": 4 + i % 4}}
        for i in range(count)
    ]  # fmt: skip
    scene = {"version": 1, "creatures": creatures}
    if terrain:
        scene["terrain"] = terrain
    return World.from_scene(scene)


@pytest.mark.parametrize("shape", SHAPES)
def test_no_two_goals_of_a_formation_overlap(shape: str) -> None:
    with _world(12) as world:
        chosen = [world.creature(f"c{i}") for i in range(12)]
        goals = formation_goals(world, chosen, (20.0, 5.0), shape)
        reaches = np.array([reach(world, c) for c in chosen])
        gap = np.linalg.norm(goals[:, None] - goals[None], axis=2)
        np.fill_diagonal(gap, np.inf)
        assert (gap >= reaches[:, None] + reaches[None]).all()
        assert len({tuple(g) for g in goals.round(6).tolist()}) == 12


def test_a_line_lies_across_the_way_the_group_comes() -> None:
    made = slots("line", 5, np.zeros(2), 1.0, np.array([1.0, 0.0]))
    assert np.allclose(made[:, 0], 0.0) and np.allclose(np.diff(made[:, 1]), 1.0)
    assert np.allclose(made.mean(axis=0), 0.0)


def test_one_creature_goes_to_the_point_and_a_bad_shape_is_named() -> None:
    with _world(2) as world:
        one = formation_goals(world, [world.creature("c0")], (3.0, 4.0), "grid")
        assert one.tolist() == [[3.0, 4.0]]
        with pytest.raises(ValueError, match="formation: must be one of ring, grid, line"):
            formation_goals(world, [world.creature("c0"), world.creature("c1")], (0, 0), "wedge")


def test_each_creature_takes_the_nearest_slot() -> None:
    with _world(5) as world:  # a row along x heading for a line far up y
        chosen = [world.creature(f"c{i}") for i in range(5)]
        goals = formation_goals(world, chosen, (5.0, 30.0), "line")
        assert np.all(np.diff(goals[:, 0]) > 0)  # nobody crosses anybody's path


def test_no_goal_lands_inside_an_obstacle() -> None:
    rock = {"obstacles": [{"shape": "box", "position": [20.0, 0.0, 0.5], "size": [3.0, 3.0, 1.0]}]}
    with _world(6, terrain=rock) as world:
        chosen = [world.creature(f"c{i}") for i in range(6)]
        goals = formation_goals(world, chosen, (20.0, 0.0), "grid")
        inside = np.abs(goals - [20.0, 0.0]).max(axis=1) < 1.5 + 0.3
        assert not inside.any()
