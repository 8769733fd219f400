"""Formation goals: spaced by reach, every shape, obstacles avoided, nearest slots."""

from __future__ import annotations

import numpy as np
import pytest

from ecs_tentacles.components import Creature, Transform
from ecs_tentacles.director.scatter import scatter
from ecs_tentacles.ground import ground_of
from ecs_tentacles.locomotion.formations import SHAPES, formation_goals, reach, slots, spacing
from ecs_tentacles.locomotion.goals import GoalBook
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


def _spread_crowd_on_the_shore(world: World) -> list[int]:
    """rocky_shore's 6 creatures and 23 more scattered over its 14 x 10 m heightfield."""
    scatter(world, world.creature_specs[world.creature("west0")], (0.0, 0.0), 7.0, 23, seed=0)
    chosen = [entity for entity, _ in world.query(Creature)]
    assert len(chosen) == 29
    return chosen


def _where(world: World, creatures: list[int]) -> np.ndarray:
    return np.array([world.component(c, Transform).pos[:2] for c in creatures])


CLICK = np.array([1.0, 0.5])  # near the middle of the shore, between its rocks


@pytest.mark.parametrize("shape", SHAPES)
def test_a_formation_gathers_a_spread_crowd_round_the_click(shape: str) -> None:
    """29 creatures spread over rocky_shore sent to a point got goals 1.5-5.7 m from it,
    each 0.3-1.9 m from where the creature already was: the group did not gather."""
    with World.from_scene("rocky_shore") as world:
        chosen = _spread_crowd_on_the_shore(world)
        goals = formation_goals(world, chosen, CLICK, shape)
        step = spacing([reach(world, c) for c in chosen])
        # reachable: every creature stands on the heightfield, none on a rock
        ground = ground_of(world)
        assert ground.heightfield is not None
        inside = 0.5 * np.asarray(ground.heightfield.size) - reach(world, chosen[0])
        assert (np.abs(goals) <= inside + 1e-9).all()
        on_top = np.column_stack([goals, ground.surface(goals)])
        assert (ground.inside_solid(on_top, 0.5 * step) < 0).all()
        gap = np.linalg.norm(goals[:, None] - goals[None], axis=2)
        np.fill_diagonal(gap, np.inf)
        assert gap.min() >= step - 1e-9
        # compact: 29 slots a spacing apart packed round the click (a hexagonal disc)
        # lie on average 2/3 of its radius away; a formation may lose a little to rocks
        # and the shore's edge but not spread back over the crowd
        disc = step * np.sqrt(len(chosen) * np.sqrt(3.0) / (2.0 * np.pi))
        distance = np.linalg.norm(goals - CLICK, axis=1)
        before = np.linalg.norm(_where(world, chosen) - CLICK, axis=1)
        assert distance.mean() <= 0.85 * before.mean()
        if shape != "line":  # a line is as long as the group; here it folds into rows
            assert distance.mean() <= 1.45 * (2.0 / 3.0) * disc
            assert distance.max() <= disc + 1.5 * step


def test_a_crowd_sent_to_a_point_crawls_there() -> None:
    with World.from_scene("rocky_shore") as world:
        chosen = _spread_crowd_on_the_shore(world)
        goals = formation_goals(world, chosen, CLICK, "ring")
        book = world.resource(GoalBook)
        for creature, goal in zip(chosen, goals, strict=True):
            book.set(creature, goal.tolist())
        start = _where(world, chosen)
        world.step(round(8.0 / world.settings.dt))
        now = _where(world, chosen)
        far = np.linalg.norm(goals - start, axis=1) > 1.0
        assert far.sum() >= 10  # most have somewhere to go
        # every creature with a way to go went its way
        assert (
            np.linalg.norm(goals - now, axis=1)[far] < np.linalg.norm(goals - start, axis=1)[far]
        ).all()
        before = np.linalg.norm(start - CLICK, axis=1).mean()
        after = np.linalg.norm(now - CLICK, axis=1).mean()
        assert after < before - 0.15
        assert world.physics.health.recoveries == 0
