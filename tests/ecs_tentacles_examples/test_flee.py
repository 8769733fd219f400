"""The flee example plugin on its bundled scene: creatures crawl away from a threat."""

from __future__ import annotations

import json

import numpy as np
import pytest

from ecs_tentacles.locomotion.goals import GoalBook
from ecs_tentacles.scene.errors import SceneError
from ecs_tentacles.scene.load import bundled_scene
from ecs_tentacles.threats.data import ThreatData
from ecs_tentacles.world import World

SECONDS = 7


def _distances(world: World) -> np.ndarray:
    """Ground distance from each creature's mantle to the roach."""
    threats, _ = world.resource(ThreatData).sources(world)
    mantles = world.transforms.pos[world.creatures.mantle_row, :2]
    return np.linalg.norm(mantles - threats[0, :2], axis=1)


def _flee(on: bool) -> tuple[np.ndarray, np.ndarray]:
    with World.from_scene("flee", plugins=None if on else {"flee": False}) as world:
        start = _distances(world)
        world.step(SECONDS * 60)
        return start, _distances(world)


def test_fleeing_creatures_end_farther_from_the_threat() -> None:
    start, fled = _flee(on=True)
    _, stayed = _flee(on=False)
    assert (fled > start + 0.1).all(), (start, fled)
    assert (fled > stayed + 0.4).all(), (stayed, fled)  # the roach came closer to the idle ones
    assert (stayed < start).all()


def _scene() -> dict:
    return json.loads(bundled_scene("flee").read_text())


def test_the_goal_points_away_and_a_threat_creature_does_not_flee_itself() -> None:
    scene = _scene()
    scene["threats"] = []
    scene["creatures"][1]["threat"] = True  # east frightens west; nothing frightens east
    scene["plugins"]["flee"]["distance"] = 2.0  # they are 1.6 m apart
    with World.from_scene(scene) as world:
        world.step(1)
        west, east = world.creature("west"), world.creature("east")
        goal = world.resource(GoalBook).positions(west)[0]
        np.testing.assert_allclose(goal[:2], [-0.8 - 1.0, 0.0], atol=0.02)  # run = 1.0 m west
        assert world.resource(GoalBook).current(east) is None


def test_out_of_reach_nobody_flees() -> None:
    scene = _scene()
    scene["plugins"]["flee"]["distance"] = 0.5  # the roach stops 0.94 m away
    with World.from_scene(scene) as world:
        world.step(3 * 60)
        assert not world.stores["locomotion.creatures"].has_goal.any()


def test_a_run_inside_the_goal_radius_is_refused() -> None:
    scene = _scene()
    scene["plugins"]["flee"]["run"] = 0.25
    with pytest.raises(SceneError, match=r"plugins\.flee\.run: must be > goal_radius \(0\.3\)"):
        World.from_scene(scene)


def test_flee_reads_dangers_from_any_plugin_and_without_one_nobody_flees() -> None:
    scene = _scene()
    del scene["threats"]
    scene["plugins"]["threats"] = False  # fine: dangers may come from any plugin
    with World.from_scene(scene) as world:
        world.step(30)
        book = world.resource(GoalBook)
        assert all(book.current(world.creature(n)) is None for n in ("west", "east"))
