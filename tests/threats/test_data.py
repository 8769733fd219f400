"""Threat data: path threats and creatures marked `threat` as sources; scene checks."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from ecs_tentacles.components import Transform
from ecs_tentacles.scene.errors import SceneError
from ecs_tentacles.threats.data import ThreatData, threat_problems
from ecs_tentacles.world import World

TENTACLES = {"count": 3, "links": 3}
STILL = [{"time": 0, "position": [0.0, 3.0, 0.2]}]


def test_a_creature_marked_threat_is_a_source_that_moves_with_it(
    make_world: Callable[..., World],
) -> None:
    data = {
        "version": 1,
        "creatures": [
            {"name": "prey", "tentacles": TENTACLES},
            {
                "name": "wolf",
                "position": [3.0, 0.0],
                "tentacles": TENTACLES,
                "threat": True,
                "goals": [{"position": [4.5, 0.0]}],
            },
        ],
        "threats": [{"name": "roach", "path": STILL}],
    }
    world = make_world(data)
    wolf = world.creature("wolf")
    body = world.component(wolf, Transform).row  # the wolf's mantle
    threats = world.resource(ThreatData)
    assert len(threats) == 2  # one path threat, one creature
    start = world.transforms.pos[body].copy()
    world.step(240)
    pos, owners = threats.sources(world)
    assert_array_equal(owners, [-1, wolf])  # path threats first, owned by nobody
    assert_allclose(pos[0], [0.0, 3.0, 0.2])
    assert_array_equal(pos[1], world.transforms.pos[body])  # the wolf's mantle, now
    assert np.linalg.norm(pos[1] - start) > 0.05  # it crawled, and its threat with it
    assert "prey" not in threats.positions(world) and list(threats.positions(world)) == ["roach"]


def test_path_threats_are_named_by_index_unless_named(make_world: Callable[..., World]) -> None:
    data = {
        "version": 1,
        "creatures": [{"tentacles": TENTACLES}],
        "threats": [{"path": STILL}, {"name": "cat", "path": STILL}, {"path": STILL}],
    }
    world = make_world(data)
    assert list(world.resource(ThreatData).positions(world)) == ["threat_0", "cat", "threat_2"]


def _scene(*threats: dict[str, Any]) -> dict[str, Any]:
    return {"version": 1, "creatures": [{"tentacles": TENTACLES}], "threats": list(threats)}


def test_scene_problems_name_their_json_path() -> None:
    late = {"time": 2, "position": [0, 0, 0]}
    early = {"time": 1, "position": [1, 0, 0]}
    scene = _scene(
        {"name": "r", "path": STILL},
        {"name": "r", "path": [late, early, {"time": 3, "position": [0, 0, 0]}]},
    )
    assert threat_problems(scene) == [
        (("threats", 1, "name"), 'duplicate name "r" (also threats[0])'),
        (("threats", 1, "path", 1, "time"), "must be > 2 (the previous key's), got 1"),
    ]
    assert threat_problems(_scene({"path": STILL}, {"path": STILL})) == []  # default names


def test_a_bad_threat_builds_nothing_and_says_where() -> None:
    same_time = [{"time": 1, "position": [0, 0, 0]}, {"time": 1, "position": [1, 0, 0]}]
    with pytest.raises(SceneError) as error:
        World.from_scene(_scene({"path": same_time}))
    assert error.value.problems == [
        "threats[0].path[1].time: must be > 1 (the previous key's), got 1"
    ]
