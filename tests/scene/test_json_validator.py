"""The scene validator skips descending into values that plainly pass a type-and-bounds
schema: it must report exactly what it reported when it descended into every value."""

from __future__ import annotations

import math
from typing import Any

import pytest
from jsonschema import Draft202012Validator, validators

from ecs_tentacles.scene import json_validator
from ecs_tentacles.scene.json_validator import StrictValidator

# the same validator without the `properties` shortcut: every value descended into
EVERY_VALUE: Any = validators.extend(
    Draft202012Validator,
    validators={"pattern": json_validator._pattern, "items": json_validator._items},
    type_checker=StrictValidator.TYPE_CHECKER,
)

SCHEMA = {
    "type": "object",
    "properties": {
        "radius": {"type": "number", "exclusiveMinimum": 0, "maximum": 10, "default": 1,
                   "x-editor": {"label": "r"}},
        "count": {"type": "integer", "minimum": 1, "maximum": 16},
        "angle": {"type": "number", "minimum": -360, "exclusiveMaximum": 360},
        "flag": {"type": "boolean"},
        "label": {"type": "string", "description": "any text"},
        "name": {"type": "string", "pattern": "^[a-z]+$"},
        "kind": {"type": ["number", "string"]},
    },
}  # fmt: skip

VALUES = [
    0.5, 10, 10.0, 0, -0.0, 1e-300, 8, 8.0, 16, 17, -360, 360, 359.999, True, False,
    math.nan, math.inf, -math.inf, "8", "octo", "octo\n", None, [1], {"a": 1}, 2**60,
]  # fmt: skip


def problems(validator: Any, instance: object) -> list[tuple[str, ...]]:
    return sorted(
        (e.message, *map(str, e.absolute_path), e.validator)
        for e in validator.iter_errors(instance)
    )


@pytest.mark.parametrize("key", sorted(SCHEMA["properties"]))
def test_each_value_gives_the_problems_a_full_descent_gives(key: str) -> None:
    fast, full = StrictValidator(SCHEMA), EVERY_VALUE(SCHEMA)
    for value in VALUES:
        assert problems(fast, {key: value}) == problems(full, {key: value}), value


def test_a_creature_of_a_crowd_gives_the_same_problems() -> None:
    from ecs_tentacles.creator.crowd import crowd_scene
    from ecs_tentacles.scene.plugins import resolve
    from ecs_tentacles.scene.schema import schema_for

    schema = schema_for(resolve(None))
    scene = crowd_scene(4, 1)
    creature = scene["creatures"][1]
    creature["heading_deg"], creature["mantle"] = 400, {"radius": math.nan, "height": 0}
    creature["tentacles"]["links"] = 8.0
    assert problems(StrictValidator(schema), scene) == problems(EVERY_VALUE(schema), scene)
    assert len(problems(EVERY_VALUE(schema), scene)) == 4
