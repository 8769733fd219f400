"""Every built-in system reads and writes only the store columns it declares.

Declarations drive `ecs-tentacles systems` and the schedule's conflict warnings, so a
declaration that leaves out a column is a lie a reader believes. Each scene below runs
its systems with every undeclared column unreadable and every column not declared in
`writes` read-only (`tests/declarations.py`), long enough that goals are reached,
suckers attach and release, threats move and fur rises.
"""

from __future__ import annotations

import copy
import json
from collections.abc import Callable
from typing import Any

import pytest

from ecs_tentacles.record.plugin import RecordPlugin
from ecs_tentacles.scene.load import resolve_scene_path
from ecs_tentacles.world import World
from tests.declarations import UndeclaredRead, columns, declared_only, step_declared
from tests.race.levels import level


def _everything() -> dict[str, Any]:
    """The hedgehog (fur, emotion, a threat) given a goal, and an octopus crawling by."""
    hedgehog = json.loads(resolve_scene_path("hedgehog_octopus").read_text())
    octopus = json.loads(resolve_scene_path("octopus").read_text())
    scene = copy.deepcopy(hedgehog)
    scene["creatures"][0]["goals"] = [{"position": [0.6, 0.3]}]
    crawler = octopus["creatures"][0]
    crawler["name"], crawler["position"] = "crawler", [0.0, -1.2]
    crawler["goals"] = [{"position": [0.25, -1.2], "radius": 0.2}, {"position": [0.9, -1.0]}]
    scene["creatures"].append(crawler)
    return scene


SCENES = {
    "everything": _everything,
    "wander": lambda: "wander",
    "flee": lambda: "flee",
    "flock": lambda: "flock",
    "follow_leader": lambda: "follow_leader",
    "race": lambda: level(rival_at=(0.0, 0.9)),  # the rival crawls to the flag and wins
}


@pytest.mark.parametrize("scene", sorted(SCENES))
def test_systems_touch_only_the_columns_they_declare(
    scene: str, make_world: Callable[..., World]
) -> None:
    world = make_world(SCENES[scene]())
    world.add_plugin(RecordPlugin())
    step_declared(world, 150)
    if scene == "everything":  # the run exercised what the declarations cover
        counts = world.events.counts
        assert counts["goal_reached"] >= 1 and counts["sucker_attached"] >= 1
        assert counts["sucker_released"] >= 1


def test_every_declared_name_is_a_store_a_column_or_a_resource(
    make_world: Callable[..., World],
) -> None:
    world = make_world(_everything())
    world.add_plugin(RecordPlugin())
    for system in world.schedule:
        for names in (system.reads, system.writes):
            assert columns(world, names)[1] == [], system.name
    for plugin in world.plugins:
        assert columns(world, plugin.hook_reads)[1] == [], plugin.key


def test_undeclared_reads_and_writes_are_caught(make_world: Callable[..., World]) -> None:
    world = make_world("octopus")
    motor_targets = world.schedule["motor_targets"]
    with declared_only(world, motor_targets):
        with pytest.raises(UndeclaredRead, match=r"transforms\.pos"):
            world.transforms.pos[0, 2] = 1.0  # motor_targets declares no transforms at all
        with pytest.raises(ValueError, match="read-only"):
            world.motors.arc[0] = 1.0  # it reads arc, it does not write it
        world.motors.target[0] = 0.0  # declared: fine
    world.transforms.pos[0, 2] += 0.0  # readable and writable again outside
    world.motors.arc[0] += 0.0
