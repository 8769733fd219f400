"""The terrain TypedDicts (`terrain.terrain_spec`) name exactly the keys the terrain
plugin's schema gives each object, require what it requires, and give its leaf types:
neither can drift."""

from __future__ import annotations

import typing

import pytest

from ecs_tentacles.terrain import terrain_spec
from ecs_tentacles.terrain.plugin import TerrainPlugin
from tests.schema_types import leaf_mismatches

_TERRAIN = TerrainPlugin.scene_schema["terrain"]
_DEFS = TerrainPlugin.defs
PAIRS = {
    "terrain": (terrain_spec.TerrainSpec, _TERRAIN),
    "terrain.heightfield": (terrain_spec.HeightfieldSpec, _DEFS["heightfield"]),
    "terrain.heightfield.noise": (
        terrain_spec.NoiseSpec,
        _DEFS["heightfield"]["properties"]["noise"],
    ),
    "terrain.obstacles[]": (terrain_spec.ObstacleSpec, _DEFS["obstacle"]),
}


def _hints(typed: type, extras: bool = False) -> dict[str, object]:
    return typing.get_type_hints(typed, include_extras=extras)


@pytest.mark.parametrize("where", PAIRS)
def test_typed_keys_are_the_schemas_keys(where: str) -> None:
    typed, schema = PAIRS[where]
    assert set(_hints(typed)) == set(schema["properties"]), where


@pytest.mark.parametrize("where", PAIRS)
def test_required_keys_are_the_schemas(where: str) -> None:
    """`Required[...]` read from the annotations (Python 3.11 misses it in string ones)."""
    typed, schema = PAIRS[where]
    hints = _hints(typed, extras=True)
    required = {key for key, hint in hints.items() if typing.get_origin(hint) is typing.Required}
    assert required == set(schema.get("required", ())), where


@pytest.mark.parametrize("where", PAIRS)
def test_leaf_types_are_the_schemas(where: str) -> None:
    typed, schema = PAIRS[where]
    assert leaf_mismatches(_hints(typed), schema) == [], where
