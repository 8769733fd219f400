"""The scene validator skips values that surely pass their schema (`plain_pass`): a crowd's
creatures are not descended into one by one, and every problem is still reported as
jsonschema reports it, at the same path."""

from __future__ import annotations

import copy
import math
from collections.abc import Iterator
from typing import Any

from jsonschema import _keywords, validators

from ecs_tentacles.creator.crowd import crowd_scene
from ecs_tentacles.scene.json_validator import StrictValidator, validator_for
from ecs_tentacles.scene.plugins import resolve
from ecs_tentacles.scene.schema import schema_for
from ecs_tentacles.scene.validate import validate_scene

# jsonschema's own `properties` and `items`: every value descended into
EVERY_VALUE: Any = validators.extend(
    StrictValidator,
    validators={"properties": _keywords.properties, "items": _keywords.items},
)

# values every leaf of a creature is replaced with, one at a time
ODD_VALUES = [
    0, -1, 0.5, 8.0, 1e9, -1e9, 2**60, True, math.nan, math.inf, "", "c 1", "octo\n",
    None, [], [1, 2], [[0]], {}, {"x": 1},
]  # fmt: skip


def problems(validator: Any, instance: object) -> list[tuple[str, ...]]:
    return sorted(
        (e.message, *map(str, e.absolute_path), str(e.validator))
        for e in validator.iter_errors(instance)
    )


def leaves(value: object, path: tuple[Any, ...] = ()) -> Iterator[tuple[Any, ...]]:
    """The path of every value inside `value`, containers included."""
    if path:
        yield path
    if isinstance(value, dict):
        for key, item in value.items():
            yield from leaves(item, (*path, key))
    elif isinstance(value, list):
        for index, item in enumerate(value):
            yield from leaves(item, (*path, index))


def replaced(data: Any, path: tuple[Any, ...], value: object) -> Any:
    out = copy.deepcopy(data)
    node = out
    for part in path[:-1]:
        node = node[part]
    node[path[-1]] = value
    return out


def with_fur_and_emotion() -> dict[str, Any]:
    """A small crowd whose first creature has fur, a groom and an emotion."""
    scene = crowd_scene(3, 5)
    first = scene["creatures"][0]
    first["fur"] = {"preset": "cat", "groom": {"count": 12, "seed": 4}}
    first["goals"] = [{"position": [1.0, 2.0], "radius": 0.5}, {"position": [0, 0]}]
    first["tentacles"]["overrides"] = [{"index": 2, "links": 6}]
    return scene


def test_every_changed_value_gives_the_problems_a_full_descent_gives() -> None:
    schema = schema_for(resolve(None))
    fast, full = validator_for(schema), EVERY_VALUE(schema)
    scene = with_fur_and_emotion()
    assert problems(fast, scene) == problems(full, scene) == []
    paths = list(leaves(scene["creatures"][0], ("creatures", 0)))
    assert len(paths) > 30
    compared = 0
    for path in paths:
        for value in ODD_VALUES:
            changed = replaced(scene, path, value)
            assert problems(fast, changed) == problems(full, changed), (path, value)
            compared += bool(problems(full, changed))
    assert compared > len(paths) * 5  # most changes are problems


def test_unknown_and_missing_keys_give_the_same_problems() -> None:
    schema = schema_for(resolve(None))
    fast, full = validator_for(schema), EVERY_VALUE(schema)
    scene = with_fur_and_emotion()
    creature = scene["creatures"][0]
    for path in [p for p in leaves(creature, ("creatures", 0)) if isinstance(p[-1], str)]:
        node = scene
        for part in path[:-1]:
            node = node[part]
        if isinstance(node, dict):
            unknown = replaced(scene, (*path[:-1], "no_such_key"), 1)
            assert problems(fast, unknown) == problems(full, unknown), path
            without = copy.deepcopy(scene)
            parent = without
            for part in path[:-1]:
                parent = parent[part]
            del parent[path[-1]]
            assert problems(fast, without) == problems(full, without), path


def test_a_problem_deep_in_a_uniform_crowd_is_reported_at_its_entry() -> None:
    scene = crowd_scene(10_000, 0, uniform=True)
    scene["creatures"][7311]["tentacles"]["links"] = 8.0
    scene["creatures"][7311]["mantle"]["radius"] = -0.1
    assert validate_scene(scene) == [
        "creatures[7311].mantle.radius: must be in [5e-05, 10], got -0.1",
        "creatures[7311].tentacles.links: must be an integer, got 8.0",
    ]


def test_a_valid_crowd_is_checked_without_descending_into_its_creatures() -> None:
    checked = []

    def counted_type(validator: Any, types: Any, instance: object, schema: Any) -> Any:
        checked.append(instance)  # each value descended into whose schema has a type
        return _keywords.type(validator, types, instance, schema)

    counting: Any = validators.extend(StrictValidator, validators={"type": counted_type})
    scene = crowd_scene(1000, 0)
    assert list(counting(schema_for(resolve(None))).iter_errors(scene)) == []
    assert len(checked) < 20  # the scene's own keys; 1,000 creatures took 60,000


def test_a_long_array_deep_in_a_uniform_crowd_is_reported_before_the_schema() -> None:
    scene = crowd_scene(10_000, 0, uniform=True)
    scene["creatures"][7311]["goals"] = [{"position": [0, 0]}] * 5000
    scene["creatures"][9]["mantle"]["radius"] = -0.1  # (the schema is not looked at)
    assert validate_scene(scene) == [
        "creatures[7311].goals: must have at most 1024 items, got 5000"
    ]
