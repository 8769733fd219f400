"""Recording points tracks (`export.track_recording.PointsTrack`): the goals track of a
world with many goals costs work in proportion to its goals, and a frame in which no
goal changed costs the same however many goals there are."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ecs_tentacles.export.recording import TakeRecorder
from ecs_tentacles.locomotion.goals import GoalBook
from ecs_tentacles.world import World
from tests.conftest import creature_scene, python_calls


def _recording(make_world: Callable[..., World], goals: int) -> tuple[World, TakeRecorder]:
    scene = creature_scene(count=3, links=3)
    scene["creatures"].append({"name": "squid", "position": [3, 0], "tentacles": {"count": 3}})
    world = make_world(scene)
    book = world.resource(GoalBook)
    for name in ("octo", "squid"):
        for k in range(goals // 2):
            book.append(world.creature(name), [0.01 * k, 2.0, 0.0])
    return world, TakeRecorder(world)


def test_the_goals_track_costs_work_in_proportion_to_its_goals(
    make_world: Callable[..., World],
) -> None:
    calls = {}
    for goals in (256, 1024):
        world, recorder = _recording(make_world, goals)
        first = python_calls(recorder.capture)  # every goal appears
        world.step()
        unchanged = python_calls(recorder.capture)  # none reached: no goal changed
        calls[goals] = (first, unchanged)
        header = recorder.take().header["goals"]
        assert len(header) == goals
        assert [entry["name"] for entry in header[: goals // 2 : 100]] == [
            f"octo/goals/goal{k}" for k in range(0, goals // 2, 100)
        ]
        assert header[goals // 2]["name"] == "squid/goals/goal0"
    (first_small, same_small), (first_large, same_large) = calls[256], calls[1024]
    assert first_large < 4.5 * first_small, calls  # scanning earlier locators made it 16
    assert same_large == same_small, calls  # per frame: array work, no per-goal Python


def test_goals_that_come_and_go_are_recorded_in_path_order(
    make_world: Callable[..., World],
) -> None:
    world, recorder = _recording(make_world, 6)
    book = world.resource(GoalBook)
    octo, squid = world.creature("octo"), world.creature("squid")
    recorder.capture()
    book.remove(book.path(octo)[1])  # from the middle: the goals after it move up
    late = book.append(squid, [5.0, 5.0, 0.0], radius=0.5)
    world.step()
    recorder.capture()
    book.clear(octo)
    world.step()
    recorder.capture()
    take = recorder.take()
    names = [entry["name"] for entry in take.header["goals"]]
    assert names == [f"{c}/goals/goal{k}" for c in ("octo", "squid") for k in range(3)] + [
        "squid/goals/goal3"
    ]
    assert take.header["goals"][-1] == {"name": "squid/goals/goal3", "creature": 1, "radius": 0.5}
    np.testing.assert_array_equal(
        take.tracks["goal_active"],
        [[1, 1, 1, 1, 1, 1, 0], [1, 0, 1, 1, 1, 1, 1], [0, 0, 0, 1, 1, 1, 1]],
    )
    np.testing.assert_allclose(take.tracks["goal_pos"][-1], [5.0, 5.0, 0.0])
    assert book.path(squid)[-1] == late
