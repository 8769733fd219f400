"""The glTF types name what the writers write: every key of a rigid and a skinned
document (with locators, goals and a terrain) is a field of its TypedDict, and every
required field is there, down to the primitives, materials and animation channels."""

from __future__ import annotations

import typing
from collections.abc import Iterator
from typing import Any

import pytest

from ecs_tentacles.export import gltf_types
from ecs_tentacles.export.gltf import build_gltf
from ecs_tentacles.export.skinned_gltf import build_skinned_gltf
from ecs_tentacles.take import Take
from tests.export.conftest import record

SCENE = {
    "version": 1,
    "terrain": {
        "heightfield": {"size": [6, 6], "resolution": 9, "height": 0.2, "noise": {"seed": 2}},
        "obstacles": [{"shape": "box", "position": [1.8, 0, 0.2], "size": [0.4, 1.0, 0.4]}],
    },
    "creatures": [
        {"name": "octo", "position": [0, 0], "tentacles": {"count": 3, "links": 3},
         "goals": [{"position": [1.0, 0.0], "radius": 0.3}]},
        {"name": "squid", "position": [-1.5, 1.0], "tentacles": {"count": 3, "links": 2}},
    ],
}  # fmt: skip


@pytest.fixture(scope="module")
def take() -> Iterator[Take]:
    world, system = record(SCENE, 4)
    yield system.take()
    world.close()


def _mismatches(value: object, kind: Any, where: str) -> Iterator[str]:
    """Where `value` strays from type `kind`: keys a TypedDict lacks, required keys absent."""
    if typing.is_typeddict(kind):
        assert isinstance(value, dict), where
        fields = typing.get_type_hints(kind)
        for key in sorted(set(value) - set(fields)):
            yield f"{where}.{key}: not a field of {kind.__name__}"
        for key in sorted(kind.__required_keys__ - set(value)):
            yield f"{where}.{key}: required by {kind.__name__}, missing"
        for key in sorted(set(value) & set(fields)):
            yield from _mismatches(value[key], fields[key], f"{where}.{key}")
    elif typing.get_origin(kind) is list:
        assert isinstance(value, list), where
        (item,) = typing.get_args(kind)
        for i, entry in enumerate(value):
            yield from _mismatches(entry, item, f"{where}[{i}]")


@pytest.mark.parametrize("form", ["rigid", "skinned"])
def test_every_key_written_is_a_field_of_its_gltf_type(take: Take, form: str) -> None:
    if form == "rigid":
        document, _ = build_gltf(take, locators=True)
    else:
        document, _, _ = build_skinned_gltf(take, locators=True)
    names = {node.get("name", "") for node in document["nodes"]}
    assert {"octo_goal0", "terrain"} <= names  # the goal's locator and the terrain are in
    assert any(node.get("extras", {}).get("ecs:locator") == "sucker" for node in document["nodes"])
    assert list(_mismatches(document, gltf_types.Document, "document")) == []


def test_a_key_the_types_lack_is_found() -> None:
    stray = {"nodes": [{"name": "a", "colour": 1}], "scenes": [{"name": "s"}]}
    assert list(_mismatches(stray, gltf_types.Document, "document")) == [
        "document.nodes[0].colour: not a field of Node",
        "document.scenes[0].nodes: required by Scene, missing",
    ]
