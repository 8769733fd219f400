"""The scene TypedDicts (`scene.spec`, `scene.scene_spec`) name exactly the keys the core
schema gives each object, with the leaf types it gives them: neither can drift."""

from __future__ import annotations

import typing
from typing import Any

import pytest

from ecs_tentacles.scene import json_types, scene_spec, spec
from ecs_tentacles.scene.schema import core_schema
from tests.schema_types import leaf_mismatches

_SCHEMA = core_schema()
_CREATURE = _SCHEMA["$defs"]["creature"]["properties"]
_PHYSICS = _SCHEMA["properties"]["physics"]
PAIRS: dict[str, tuple[Any, dict[str, Any]]] = {
    "scene": (scene_spec.SceneSpec, _SCHEMA),
    "physics": (scene_spec.PhysicsSpec, _PHYSICS),
    "physics.lod": (scene_spec.LodSpec, _PHYSICS["properties"]["lod"]),
    "physics.lod.focus": (
        scene_spec.FocusSpec,
        _PHYSICS["properties"]["lod"]["properties"]["focus"],
    ),
    "render": (scene_spec.RenderSpec, _SCHEMA["properties"]["render"]),
    "creature": (spec.CreatureSpec, _SCHEMA["$defs"]["creature"]),
    "creature.mantle": (spec.MantleSpec, _CREATURE["mantle"]),
    "creature.tentacles": (spec.TentaclesSpec, _CREATURE["tentacles"]),
    "creature.tentacles.overrides[]": (
        spec.TentacleOverride,
        _SCHEMA["$defs"]["tentacle_override"],
    ),
}


def _keys(typed: Any) -> set[str]:
    return set(typed.__required_keys__) | set(typed.__optional_keys__)


def _hints(typed: Any, extras: bool = False) -> dict[str, Any]:
    """The TypedDict's annotations, evaluated (`JsonValue` resolved where it is defined)."""
    return typing.get_type_hints(typed, localns=vars(json_types), include_extras=extras)


def _required(typed: Any) -> set[str]:
    """Required keys, reading `Required[...]` itself (Python 3.11 misses it in string
    annotations)."""
    hints = _hints(typed, extras=True)
    marked = {key for key, hint in hints.items() if typing.get_origin(hint) is typing.Required}
    loose = {key for key, hint in hints.items() if typing.get_origin(hint) is typing.NotRequired}
    return (set(typed.__required_keys__) - loose) | marked


@pytest.mark.parametrize("where", PAIRS)
def test_typed_keys_are_the_schemas_keys(where: str) -> None:
    typed, schema = PAIRS[where]
    assert _keys(typed) == set(schema["properties"]), where


@pytest.mark.parametrize("where", PAIRS)
def test_keys_the_schema_requires_are_required(where: str) -> None:
    typed, schema = PAIRS[where]
    assert set(schema.get("required", ())) <= _required(typed), where


@pytest.mark.parametrize("where", PAIRS)
def test_leaf_types_are_the_schemas(where: str) -> None:
    typed, schema = PAIRS[where]
    assert leaf_mismatches(_hints(typed), schema) == [], where
