"""Dangers (`ecs_tentacles.behaviour`): whoever makes them, whoever fears them. A user's
plugin's danger makes the flee example run with the threats plugin off; sources join;
without any, nothing is dangerous."""

from __future__ import annotations

import json

import numpy as np

from ecs_tentacles.behaviour import Dangers, DangerSource, dangers, placeable
from ecs_tentacles.components import Creature
from ecs_tentacles.locomotion.goals import GoalBook
from ecs_tentacles.plugin import Plugin
from ecs_tentacles.registry import App
from ecs_tentacles.scene.load import bundled_scene
from ecs_tentacles.world import World

SPOT = np.array([[-0.4, 0.0, 0.0]])  # just east of "west" (at -0.8, 0)


class Beacon(Plugin):
    """A user's plugin: one fixed danger, owned by no creature, that cannot be placed."""

    name = "beacon"

    def build(self, app: App) -> None:
        app.add(Dangers, DangerSource(sense=lambda world: (SPOT, np.array([-1]))))


def _scene(threats: bool) -> dict:
    scene = json.loads(bundled_scene("flee").read_text())
    if not threats:
        del scene["threats"]
    scene["plugins"]["flee"]["distance"] = 1.0
    return scene


def test_a_users_danger_makes_the_flee_example_run_without_the_threats_plugin() -> None:
    with World.from_scene(_scene(False), plugins={"threats": False}) as world:
        assert dangers(world)[0].shape == (0, 3) and placeable(world) is None
        world.add_plugin(Beacon())
        world.step(1)
        positions, owners = dangers(world)
        np.testing.assert_array_equal(positions, SPOT)
        np.testing.assert_array_equal(owners, [-1])
        goal = world.resource(GoalBook).positions(world.creature("west"))[0]
        assert goal[0] < -0.8 - 0.5  # away from the danger, to the west


def test_sources_join_and_the_threats_plugin_places_and_removes() -> None:
    with World.from_scene(_scene(True)) as world:
        world.add_plugin(Beacon())
        world.step(1)
        positions, owners = dangers(world)
        assert len(positions) == 2 and list(owners) == [-1, -1]  # the roach, the beacon
        source = placeable(world)
        assert source is not None and source.drop and source.placed and source.remove
        entity = source.drop(world, [2.0, 2.0], "moth")
        assert source.placed(world)[entity] == "moth" and len(dangers(world)[0]) == 3
        source.remove(world, entity)
        assert len(dangers(world)[0]) == 2


def test_travel_sends_and_stops_a_creature_through_locomotions_goals() -> None:
    from ecs_tentacles.behaviour import travel

    with World.from_scene(_scene(False), plugins={"threats": False}) as world:
        west = world.creature("west")
        row = world.component(west, Creature).row
        way = travel(world)
        assert not way.going(world)[row]
        way.send(world, west, (-3.0, 1.0), 0.25)
        assert way.going(world)[row]
        goal = world.resource(GoalBook).positions(west)[0]
        np.testing.assert_allclose(goal[:2], [-3.0, 1.0])
        way.stop(world, west)
        assert not way.going(world)[row] and world.resource(GoalBook).current(west) is None


def test_without_locomotion_travel_says_so_in_one_line() -> None:
    import pytest

    from ecs_tentacles.behaviour import travel

    with World.from_scene({"version": 1, "creatures": [{}]}, plugins={"locomotion": False,
                          "suckers": False}) as world:  # fmt: skip
        with pytest.raises(LookupError, match=r"^no plugin sends creatures anywhere"):
            travel(world)
