"""The follow_leader example plugin on its bundled scene: followers close in and keep a gap."""

from __future__ import annotations

import json
from typing import Any

import numpy as np
import pytest

from ecs_tentacles.components import Creature
from ecs_tentacles.scene.errors import SceneError
from ecs_tentacles.scene.load import bundled_scene
from ecs_tentacles.world import World

GAP, GOAL_RADIUS = 0.8, 0.3  # the scene's gap, the default goal radius


def _to_leader(world: World) -> np.ndarray:
    """Ground distance from each follower (north, south) to the leader."""
    rows = [world.component(world.creature(n), Creature).row for n in ("leader", "north", "south")]
    mantles = world.transforms.pos[world.creatures.mantle_row[rows], :2]
    return np.linalg.norm(mantles[1:] - mantles[0], axis=1)


def _scene() -> dict[str, Any]:
    scene: dict[str, Any] = json.loads(bundled_scene("follow_leader").read_text())
    return scene


def test_followers_end_closer_to_the_leader_and_keep_the_gap() -> None:
    with World.from_scene("follow_leader") as world:
        start = _to_leader(world)
        world.step(8 * 60)
        end = _to_leader(world)
        assert (end < start - 0.3).all(), (start, end)
        assert (end > GAP - 0.1).all() and (end < GAP + GOAL_RADIUS + 0.1).all(), end
        assert not world.stores["locomotion.creatures"].has_goal.any()  # arrived: everybody stopped


def test_without_the_plugin_the_followers_stay() -> None:
    scene = _scene()
    scene["plugins"]["follow_leader"] = False
    for creature in scene["creatures"]:
        creature.pop("follow", None)
    with World.from_scene(scene) as world:
        start = _to_leader(world)
        world.step(2 * 60)
        assert (_to_leader(world) >= start - 0.01).all()  # the leader crawls away from them


@pytest.mark.parametrize(
    ("leader", "message"),
    [
        ("north", "creatures[1].follow: a creature cannot follow itself"),
        ("boss", 'creatures[1].follow: no creature named "boss" (there are: leader, north, south)'),
    ],
)
def test_a_leader_must_be_another_creature_of_the_scene(leader: str, message: str) -> None:
    scene = _scene()
    scene["creatures"][1]["follow"] = leader
    with pytest.raises(SceneError) as error:
        World.from_scene(scene)
    assert str(error.value) == message


def test_follow_is_refused_without_the_plugin() -> None:
    scene = _scene()
    scene["plugins"]["follow_leader"] = False
    with pytest.raises(SceneError, match=r"creatures\[1\]\.follow: unknown key"):
        World.from_scene(scene)
