"""Goals and paths: the GoalBook API and the `goals` system that reaches them."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from ecs_tentacles.components import Transform
from ecs_tentacles.locomotion.components import Goal
from ecs_tentacles.locomotion.goals import DEFAULT_RADIUS, GoalBook
from ecs_tentacles.world import World
from tests.conftest import creature_scene, python_calls


def _world(make_world: Callable[..., World], **creature: Any) -> World:
    scene = creature_scene(count=3, links=3)
    scene["creatures"][0].update(creature)
    return make_world(scene)


def _orders(world: World, goals: list[int]) -> list[int]:
    return [world.component(g, Goal).order for g in goals]


def test_set_append_remove_clear(make_world: Callable[..., World]) -> None:
    world = _world(make_world)
    octo = world.creature("octo")
    store, row = world.stores["locomotion.creatures"], 0
    assert world.resource(GoalBook).path(octo) == []
    assert world.resource(GoalBook).current(octo) is None
    assert world.resource(GoalBook).positions(octo).shape == (0, 3)
    assert not store.has_goal[row]

    a = world.resource(GoalBook).set(octo, [1.0, 2.0])
    b = world.resource(GoalBook).append(octo, [3.0, 4.0, 0.5], radius=0.1)
    c = world.resource(GoalBook).append(octo, (-1.0, 0.0))
    assert world.resource(GoalBook).path(octo) == [a, b, c]
    assert world.resource(GoalBook).current(octo) == a
    assert _orders(world, [a, b, c]) == [0, 1, 2]
    assert_array_equal(
        world.resource(GoalBook).positions(octo),
        [[1.0, 2.0, 0.0], [3.0, 4.0, 0.5], [-1.0, 0.0, 0.0]],
    )
    goal_b = world.component(b, Goal)
    assert (goal_b.owner, goal_b.radius) == (octo, 0.1)
    assert world.component(a, Goal).radius == DEFAULT_RADIUS
    assert store.has_goal[row]
    assert_array_equal(store.goal[row], [1.0, 2.0, 0.0])
    assert store.goal_radius[row] == DEFAULT_RADIUS

    world.resource(GoalBook).remove(b)  # from the middle: the rest close ranks
    assert world.resource(GoalBook).path(octo) == [a, c]
    assert _orders(world, [a, c]) == [0, 1]
    assert world.try_component(b, Goal) is None

    world.resource(GoalBook).remove(
        a
    )  # the current one: the next becomes current, mirrored in the store
    assert world.resource(GoalBook).current(octo) == c
    assert _orders(world, [c]) == [0]
    assert_array_equal(store.goal[row], [-1.0, 0.0, 0.0])

    d = world.resource(GoalBook).set(octo, [5.0, 5.0], radius=2.0)  # replaces the whole path
    assert world.resource(GoalBook).path(octo) == [d]
    assert world.try_component(c, Goal) is None
    assert_array_equal(store.goal[row], [5.0, 5.0, 0.0])
    assert store.goal_radius[row] == 2.0

    path = world.resource(GoalBook).path(octo)
    path.append(12345)  # path() is a copy
    assert world.resource(GoalBook).path(octo) == [d]

    world.resource(GoalBook).clear(octo)
    assert world.resource(GoalBook).path(octo) == []
    assert world.resource(GoalBook).current(octo) is None
    assert world.try_component(d, Goal) is None
    assert not store.has_goal[row]
    world.resource(GoalBook).clear(octo)  # clearing nothing is fine
    assert world.resource(GoalBook).path(octo) == []


def test_scene_goals_form_the_path(make_world: Callable[..., World]) -> None:
    world = _world(make_world, goals=[{"position": [1, 0]}, {"position": [2, 1, 0.2], "radius": 1}])
    octo = world.creature("octo")
    path = world.resource(GoalBook).path(octo)
    assert _orders(world, path) == [0, 1]
    assert_array_equal(world.resource(GoalBook).positions(octo), [[1, 0, 0], [2, 1, 0.2]])
    assert [world.component(g, Goal).radius for g in path] == [DEFAULT_RADIUS, 1.0]


@pytest.mark.parametrize(
    ("position", "radius", "message"),
    [
        ([1.0], 0.3, "goal position must be 2 or 3 finite numbers, got [1.0]"),
        ([1.0, 2.0, 3.0, 4.0], 0.3, "goal position must be 2 or 3 finite numbers"),
        ([[1.0, 2.0]], 0.3, "goal position must be 2 or 3 finite numbers"),
        ([np.nan, 0.0], 0.3, "goal position must be 2 or 3 finite numbers"),
        ([np.inf, 0.0], 0.3, "goal position must be 2 or 3 finite numbers"),
        ([1.0, 0.0], 0.0, "goal radius must be > 0, got 0.0"),
        ([1.0, 0.0], -1.0, "goal radius must be > 0, got -1.0"),
        ([1.0, 0.0], np.nan, "goal radius must be > 0, got nan"),
    ],
)
def test_bad_goals_are_refused_and_change_nothing(
    make_world: Callable[..., World], position: list[float], radius: float, message: str
) -> None:
    world = _world(make_world)
    octo = world.creature("octo")
    first = world.resource(GoalBook).set(octo, [1.0, 1.0])
    with pytest.raises(ValueError, match="^" + message.replace("[", r"\[").replace("]", r"\]")):
        world.resource(GoalBook).append(octo, position, radius)
    assert world.resource(GoalBook).path(octo) == [first]
    assert_array_equal(world.stores["locomotion.creatures"].goal[0], [1.0, 1.0, 0.0])


def test_a_refused_set_keeps_the_old_path(make_world: Callable[..., World]) -> None:
    # e.g. a click that misses the ground gives nan: the creature should keep its path
    world = _world(make_world)
    octo = world.creature("octo")
    path = [
        world.resource(GoalBook).set(octo, [1.0, 1.0]),
        world.resource(GoalBook).append(octo, [2.0, 1.0]),
    ]
    with pytest.raises(ValueError, match=r"^goal position must be 2 or 3 finite numbers"):
        world.resource(GoalBook).set(octo, [np.nan, 0.0])
    with pytest.raises(ValueError, match=r"^goal radius must be > 0, got 0"):
        world.resource(GoalBook).set(octo, [1.0, 0.0], radius=0)
    assert world.resource(GoalBook).path(octo) == path
    assert world.stores["locomotion.creatures"].has_goal[0]


def test_goals_belong_to_creatures(make_world: Callable[..., World]) -> None:
    world = _world(make_world)
    octo = world.creature("octo")
    goal = world.resource(GoalBook).set(octo, [1.0, 1.0])
    with pytest.raises(KeyError):
        world.resource(GoalBook).append(goal, [0.0, 0.0])


def test_goal_on_the_creature_is_reached_on_the_first_frame(
    make_world: Callable[..., World],
) -> None:
    world = _world(make_world)
    octo = world.creature("octo")
    reached: list[dict[str, Any]] = []
    world.events.on("goal_reached", lambda **kw: reached.append(kw))
    here = world.resource(GoalBook).set(octo, [0.05, -0.05])
    there = world.resource(GoalBook).append(octo, [3.0, 0.0])
    world.step(1)
    assert len(reached) == 1
    event = reached[0]
    assert (event["world"], event["creature"], event["goal"]) == (world, octo, here)
    assert_array_equal(event["position"], [0.05, -0.05, 0.0])
    assert world.resource(GoalBook).path(octo) == [there]
    assert world.resource(GoalBook).current(octo) == there
    assert world.component(there, Goal).order == 0
    assert world.try_component(here, Goal) is None
    assert_array_equal(world.stores["locomotion.creatures"].goal[0], [3.0, 0.0, 0.0])
    assert world.events.counts["goal_reached"] == 1
    world.step(5)
    assert world.events.counts["goal_reached"] == 1  # far away: not reached


def test_goals_are_reached_in_path_order(make_world: Callable[..., World]) -> None:
    # all but the last are within reach of the mantle, nearest last: the path order wins
    world = _world(make_world)
    octo = world.creature("octo")
    reached: list[list[float]] = []
    world.events.on("goal_reached", lambda **kw: reached.append(kw["position"][:2].tolist()))
    path = [[0.0, 0.0], [0.25, 0.0], [0.0, -0.2], [0.1, 0.05], [2.0, 0.0]]
    for position in path:
        world.resource(GoalBook).append(octo, position)
    world.step(8)
    assert reached == path[:4]
    assert_allclose(world.resource(GoalBook).positions(octo), [[2.0, 0.0, 0.0]])
    assert world.events.counts["goal_reached"] == 4


def test_reaching_is_measured_in_the_ground_plane(make_world: Callable[..., World]) -> None:
    world = _world(make_world)
    octo = world.creature("octo")
    world.resource(GoalBook).set(octo, [0.0, 0.0, 5.0], radius=0.05)  # straight above the mantle
    world.step(1)
    assert world.resource(GoalBook).path(octo) == []
    assert world.events.counts["goal_reached"] == 1


def test_goal_just_outside_its_radius_is_not_reached(make_world: Callable[..., World]) -> None:
    world = _world(make_world)
    octo = world.creature("octo")
    mantle = world.component(octo, Transform).pos[:2].copy()
    far = world.resource(GoalBook).set(octo, mantle + np.array([0.31, 0.0]), radius=0.3)
    world.step(1)
    assert world.resource(GoalBook).path(octo) == [far]
    world.resource(GoalBook).set(octo, mantle + np.array([0.29, 0.0]), radius=0.3)
    world.step(1)
    assert world.resource(GoalBook).path(octo) == []


def test_building_and_clearing_a_path_is_linear_in_its_goals(
    make_world: Callable[..., World],
) -> None:
    """A scene's path of n goals is built by n appends and dropped by one clear: four
    times the goals cost about four times the work (each append renumbering the whole
    path made it sixteen: 64 creatures x 1,024 goals took 37 s to build)."""
    world = _world(make_world)
    octo = world.creature("octo")
    book = world.resource(GoalBook)

    def path_of(n: int) -> Callable[[], None]:
        def build_and_clear() -> None:
            for k in range(n):
                book.append(octo, [0.01 * k, 1.0, 0.0])
            book.clear(octo)

        return build_and_clear

    path_of(4)()  # the first calls import and cache what they need
    small, large = python_calls(path_of(256)), python_calls(path_of(1024))
    assert large < 4.5 * small, (small, large)
    assert book.path(octo) == [] and not world.stores["locomotion.creatures"].has_goal[0]
    assert len(list(world.query(Goal))) == 0
