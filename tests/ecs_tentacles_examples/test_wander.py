"""The wander example plugin on its bundled scene: idle creatures get goals and travel."""

from __future__ import annotations

import numpy as np
import pytest

from ecs_tentacles.scene.errors import SceneError
from ecs_tentacles.world import World

SECONDS = 6


Run = tuple[np.ndarray, dict[str, list[np.ndarray]], np.ndarray]


def _run(seed: int | None = None, seconds: float = SECONDS) -> Run:
    """Mantle start, the goals each creature was given, and each mantle's path length."""
    with World.from_scene("wander", seed=seed) as world:
        start = world.transforms.pos[world.creatures.mantle_row].copy()
        given: dict[str, list[np.ndarray]] = {"left": [], "right": []}
        assert not world.stores["locomotion.creatures"].has_goal.any()  # the scene gives them none
        before, path = start, np.zeros(len(start))
        for _ in range(round(seconds * 60)):
            world.step()
            now = world.transforms.pos[world.creatures.mantle_row].copy()
            path += np.linalg.norm(now[:, :2] - before[:, :2], axis=1)
            before = now
            for row, entity in enumerate(world.creatures.entity):
                goal = world.stores["locomotion.creatures"].goal[row, :2].copy()
                history = given[world.creature_name(int(entity))]
                if world.stores["locomotion.creatures"].has_goal[row] and not (
                    history and np.array_equal(history[-1], goal)
                ):
                    history.append(goal)
        return start, given, path


@pytest.fixture(scope="module")
def wandered() -> Run:
    return _run()


def test_idle_creatures_get_goals_near_them_and_crawl(wandered: Run) -> None:
    start, given, path = wandered
    for row, name in enumerate(("left", "right")):
        goals = given[name]
        assert len(goals) >= 2, f"{name} got {len(goals)} goal(s) in {SECONDS} s"
        first = np.linalg.norm(goals[0] - start[row, :2])
        assert 0.5 - 0.05 <= first <= 1.0 + 0.05  # between radius / 2 and radius (+ settling)
    assert (path > 0.4).all(), path
    print(path)  # metres crawled (about 0.1 m/s)


def test_the_same_seed_repeats_exactly_and_another_differs(wandered: Run) -> None:
    _, given, path = wandered
    again = _run()
    np.testing.assert_array_equal(path, again[2])
    for name in given:
        np.testing.assert_array_equal(np.array(given[name]), np.array(again[1][name]))
    other = _run(seed=6, seconds=0.1)
    assert not np.array_equal(np.array(given["left"][0]), np.array(other[1]["left"][0]))


def test_a_snapshot_repeats_the_wandering() -> None:
    with World.from_scene("wander") as world:
        world.step(200)
        snap = world.snapshot()
        world.step(100)
        goals, end = world.stores["locomotion.creatures"].goal.copy(), world.transforms.pos.copy()
        world.restore(snap)
        world.step(100)
        np.testing.assert_array_equal(world.stores["locomotion.creatures"].goal, goals)
        np.testing.assert_array_equal(world.transforms.pos, end)


def test_a_radius_too_small_for_its_goals_is_refused() -> None:
    with pytest.raises(SceneError, match=r"plugins\.wander\.radius: must be > 2 x goal_radius"):
        World.from_scene("wander", plugins={"wander": {"radius": 0.4, "goal_radius": 0.3}})
