"""What the TypedDict-against-schema tests share (tests/scene/test_scene_spec.py,
tests/terrain/test_terrain_spec.py): a JSON Schema leaf type's Python type, and where a
TypedDict's annotations differ from the leaf types its schema object gives."""

from __future__ import annotations

from collections.abc import Mapping

LEAVES = {"integer": int, "number": float, "boolean": bool, "string": str}


def leaf_mismatches(hints: Mapping[str, object], schema: Mapping[str, object]) -> list[str]:
    """`key: annotation for schema type` for each leaf property of `schema` whose
    annotation in `hints` is not the type the schema gives (none: they agree)."""
    properties = schema["properties"]
    assert isinstance(properties, dict)
    found = []
    for key, node in properties.items():
        kind = node.get("type")
        if isinstance(kind, str) and kind in LEAVES and hints[key] is not LEAVES[kind]:
            found.append(f"{key}: {hints[key]} for {kind}")
    return found
