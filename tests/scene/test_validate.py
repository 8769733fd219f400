"""Exact one-line messages of validate_scene (with_defaults is tested in test_schema.py)."""

from __future__ import annotations

from typing import Any

import pytest

from ecs_tentacles.scene.validate import format_path, validate_scene
from tests.scene.bad_scenes import (
    BAD_SCENES,
    TENTACLE_KEYS,
    TOP_KEYS,
    scene,
    tentacles,
)


@pytest.mark.parametrize(
    ("data", "expected"),
    [pytest.param(data, expected, id=name) for name, data, expected in BAD_SCENES],
)
def test_bad_scene_gives_one_exact_problem(data: object, expected: str) -> None:
    assert validate_scene(data) == [expected]


def test_bad_scene_names_are_distinct() -> None:
    assert len({name for name, _, _ in BAD_SCENES}) == len(BAD_SCENES) >= 18


def test_minimal_scene_is_valid() -> None:
    assert validate_scene({"version": 1}) == []


def test_full_scene_is_valid() -> None:
    data = scene(
        {"name": "octo", "tentacles": {"count": 6, "overrides": [{"index": 5, "links": 3}]}},
        {"goals": [{"position": [1, 2, 0.5], "radius": 1}], "mantle": {"radius": 0.2}},
        systems=["my_pkg.systems:Wiggle"],
        physics={"gravity": [0, 0, -1.6], "substeps": 4},
        seed=7,
    )
    assert validate_scene(data) == []


def test_touching_mantles_do_not_overlap() -> None:
    assert validate_scene(scene({"position": [0, 0]}, {"position": [0.3, 0]})) == []


def test_many_problems_are_all_reported_sorted_by_path() -> None:
    creatures: list[dict[str, Any]] = [{} for _ in range(11)]
    creatures[10] = tentacles(count=0)
    creatures[2] = {"name": "my octo", "tentacles": {"end_scale": 1.7, "lenght": 1}}
    data = scene(*creatures, physics={"fps": 0, "substeps": 0.5}, colour="red", seed=-1)
    del data["version"]
    assert validate_scene(data) == [
        f"colour: unknown key (allowed: {TOP_KEYS})",
        "creatures[2].name: must be letters, digits and _, not starting with a digit, "
        'got "my octo"',
        "creatures[2].tentacles.end_scale: must be in (0, 1], got 1.7",
        f"creatures[2].tentacles.lenght: unknown key (allowed: {TENTACLE_KEYS})",
        "creatures[10].tentacles.count: must be in [1, 16], got 0",
        "physics.fps: must be in [4, 1000], got 0",
        "physics.substeps: must be an integer, got 0.5",
        "seed: must be >= 0, got -1",
        "version: is required",
    ]


def test_many_semantic_problems_are_all_reported_sorted() -> None:
    data = scene(
        {"name": "a", "position": [0, 0], "tentacles": {"overrides": [{"index": 8}, {"index": 8}]}},
        {"name": "a", "position": [0.1, 0]},
        {"name": "b", "position": [0, 0.1]},
    )
    assert validate_scene(data) == [
        "creatures[0].tentacles.overrides[0].index: must be < count (8), got 8",
        "creatures[0].tentacles.overrides[1].index: duplicate index 8 "
        "(also creatures[0].tentacles.overrides[0])",
        "creatures[0].tentacles.overrides[1].index: must be < count (8), got 8",
        'creatures[1].name: duplicate name "a" (also creatures[0])',
    ]


def test_semantic_checks_wait_for_the_schema() -> None:
    data = scene({"name": "a"}, {"name": "a", "tentacles": {"end_scale": 2}})
    assert validate_scene(data) == ["creatures[1].tentacles.end_scale: must be in (0, 1], got 2"]


def test_long_values_are_shortened_to_one_line() -> None:
    (problem,) = validate_scene(list(range(100)))
    shown = "[0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16..."
    assert problem == f"scene: must be an object, got {shown}"


def test_format_path() -> None:
    assert format_path([]) == "scene"
    assert format_path(["creatures", 1, "tentacles", "end_scale"]) == (
        "creatures[1].tentacles.end_scale"
    )
    assert format_path(["$schema"]) == "$schema"
    assert format_path(["my key", 0]) == '["my key"][0]'


def test_a_creature_entry_is_checked_as_one_more_creature_of_its_scene() -> None:
    from ecs_tentacles.scene.load import bundled_scene, load_scene_plugins
    from ecs_tentacles.scene.validate import validated_creature

    scene, plugins = load_scene_plugins(bundled_scene("herding_1_field"))
    problems, entry = validated_creature({"name": "new", "mantle": {}}, scene, plugins)
    assert problems == [] and entry is not None  # the level's `game` is there
    assert entry["tentacles"]["count"] == 8 and entry["position"] == [0, 0]  # defaults in
    problems, entry = validated_creature(
        {"name": "new", "mantle": {"radius": -1}, "tentacles": {"overrides": [{"index": 9}]}},
        scene,
        plugins,
    )
    assert entry is None
    assert problems == ["creature.mantle.radius: must be in [5e-05, 10], got -1"]
    problems, _ = validated_creature({"tentacles": {"overrides": [{"index": 9}]}}, scene, plugins)
    assert problems == ["creature.tentacles.overrides[0].index: must be < count (8), got 9"]
