"""Shard plans: the scene's `shards` field, creatures that can never meet, packing."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import pytest

from ecs_tentacles.distributed.registries import Reach, ShardGroups, ShardReaches
from ecs_tentacles.distributed.shards import pack, plan_shards, scene_plugins, segment_distance
from ecs_tentacles.plugin import Plugin
from ecs_tentacles.registry import App
from ecs_tentacles.scene.errors import SceneError
from ecs_tentacles.scene.load import load_scene


def scene(
    *positions: tuple[float, float], goals: dict[int, list[float]] | None = None
) -> dict[str, Any]:
    creatures = [
        {
            "name": f"c{i}",
            "position": list(p),
            "goals": [{"position": goals[i]}] if goals and i in goals else [],
        }
        for i, p in enumerate(positions)
    ]
    return {"version": 1, "name": "s", "creatures": creatures}


def test_creatures_far_apart_are_separate_islands_and_near_ones_join() -> None:
    data = load_scene(scene((0, 0), (2.2, 0), (30, 0), (60, 0)))
    plan = plan_shards(data, seconds=1.0, tasks=8)
    assert plan.shards == [[0, 1], [2], [3]] and plan.islands == 3 and not plan.declared
    assert plan.describe() == "3 shards from 3 sets of creatures that never meet"
    # a long bake lets them all crawl into each other's reach
    everything = plan_shards(data, seconds=200.0, tasks=8)
    assert everything.shards == [[0, 1, 2, 3]]
    assert everything.describe() == "1 shard: every creature may meet another during the bake"


def test_creatures_heading_apart_stay_apart_where_discs_would_not() -> None:
    # they walk apart all the bake: their capsules never meet; a goal reached early
    # leaves c0 free to crawl anywhere within its travel (a disc), so they may meet
    away = load_scene(scene((0, 0), (4, 0), goals={0: [-20, 0], 1: [24, 0]}))
    idle = load_scene(scene((0, 0), (4, 0), goals={0: [-0.5, 0], 1: [24, 0]}))
    assert plan_shards(away, seconds=30.0, tasks=4).shards == [[0], [1]]
    assert plan_shards(idle, seconds=30.0, tasks=4).shards == [[0, 1]]


def test_islands_are_packed_into_at_most_tasks_shards_balanced() -> None:
    data = load_scene(scene(*((40.0 * i, 0.0) for i in range(5))))
    islands = [[0], [1], [2], [3], [4]]
    assert pack(islands, data["creatures"], 2) == [[0, 2, 4], [1, 3]]
    assert pack(islands, data["creatures"], 1) == [[0, 1, 2, 3, 4]]


def test_declared_shards_are_used_as_they_are() -> None:
    raw = scene((0, 0), (1.5, 0), (3, 0))
    raw["shards"] = [["c2", "c0"], ["c1"]]
    data = load_scene(raw)
    plan = plan_shards(data, seconds=1.0, tasks=8)
    assert plan.shards == [[0, 2], [1]] and plan.declared


@pytest.mark.parametrize(
    ("shards", "problems"),
    [
        ([["c0", "c1"], ["c0"]], ['shards[1][0]: "c0" is already in shards[0][0]']),
        ([["c0"], ["c1", "c9"]], ['shards[1][1]: no creature named "c9"']),
        ([["c0"]], ['shards: creature "c1" is in no shard']),
        ([], ["shards: must have 1 to 16384 items, got 0"]),
    ],
)
def test_bad_shards_get_one_line_each_with_the_json_path(
    shards: list[list[str]], problems: list[str]
) -> None:
    raw = scene((0, 0), (1.5, 0))  # apart: the only problems are the shards'
    raw["shards"] = shards
    with pytest.raises(SceneError) as caught:
        load_scene(raw)
    assert caught.value.problems == problems


def test_segment_distance() -> None:
    p0, p1 = np.array([[0.0, 0.0], [0.0, 0.0]]), np.array([[2.0, 0.0], [2.0, 0.0]])
    q0, q1 = np.array([[1.0, 1.0], [3.0, 3.0]]), np.array([[1.0, -1.0], [3.0, 4.0]])
    np.testing.assert_allclose(segment_distance(p0, p1, q0, q1), [0.0, np.hypot(1, 3)])


def test_a_threat_creature_shares_a_shard_with_the_creatures_it_may_rouse() -> None:
    raw = scene((0, 0), (50, 0), (100, 0), (150, 0))
    raw["creatures"][0]["threat"] = True
    raw["creatures"][2]["emotion"] = {}
    assert plan_shards(load_scene(raw), seconds=1.0, tasks=8).shards == [[0, 2], [1], [3]]
    raw["shards"] = [["c0", "c1"], ["c2"], ["c3"]]
    declared = plan_shards(load_scene(raw), seconds=1.0, tasks=8)
    assert declared.shards == [[0, 1, 2], [3]]


def test_a_scene_without_creatures_is_one_empty_shard() -> None:
    assert plan_shards(load_scene({"version": 1}), seconds=1.0, tasks=8).shards == [[]]


def test_without_locomotion_creatures_reach_only_as_far_as_their_bodies() -> None:
    raw = scene((0, 0), (5, 0))
    for creature in raw["creatures"]:
        del creature["goals"]  # a locomotion key
    raw["plugins"] = {"locomotion": False, "suckers": False}
    # no crawl: however long the bake, 5 m apart never meet
    assert plan_shards(load_scene(raw), seconds=200.0, tasks=8).shards == [[0], [1]]
    del raw["plugins"]
    assert plan_shards(load_scene(raw), seconds=200.0, tasks=8).shards == [[0, 1]]


class Drifter(Plugin):
    """Lets every creature drift 10 m in the bake, and keeps c0 and c3 in one shard."""

    name = "drifter"

    def build(self, app: App) -> None:
        app.add(ShardReaches, self.reach)
        app.add(ShardGroups, self.groups)

    def reach(self, creature: Mapping[str, Any], seconds: float) -> Reach:
        return Reach(radius=10.0)

    def groups(self, creatures: Sequence[Mapping[str, Any]]) -> list[list[int]]:
        return [[0, 3]]


def test_plugins_widen_reaches_and_group_creatures() -> None:
    data = load_scene(scene((0, 0), (50, 0), (65, 0), (150, 0)))
    plugins = scene_plugins(data)
    assert plan_shards(data, seconds=1.0, tasks=8, plugins=plugins).shards == [
        [0],
        [1],
        [2],
        [3],
    ]
    drifting = plan_shards(data, seconds=1.0, tasks=8, plugins=[*plugins, Drifter()])
    assert drifting.shards == [[0, 3], [1, 2]] and drifting.islands == 2
