"""The bundled scene schema, and with_defaults filling in the defaults it declares."""

from __future__ import annotations

import copy
import json
from collections.abc import Iterator
from typing import Any

from jsonschema import Draft202012Validator

from ecs_tentacles.scene.defaults import with_defaults
from ecs_tentacles.scene.schema import load_schema
from ecs_tentacles.scene.validate import validate_scene


def subschemas(node: Any, where: str = "#") -> Iterator[tuple[str, dict[str, Any]]]:
    """Every schema object under ``node`` (properties, items, $defs, ...), with a pointer."""
    if not isinstance(node, dict):
        return
    yield where, node
    for key in ("properties", "$defs"):
        for name, sub in node.get(key, {}).items():
            yield from subschemas(sub, f"{where}/{key}/{name}")
    for key in ("items", "additionalProperties"):
        yield from subschemas(node.get(key), f"{where}/{key}")


def test_schema_is_a_valid_draft_2020_12_schema() -> None:
    Draft202012Validator.check_schema(load_schema())


def test_schema_is_loaded_once() -> None:
    assert load_schema() is load_schema()


def test_every_object_forbids_unknown_keys() -> None:
    objects = [(where, s) for where, s in subschemas(load_schema()) if s.get("type") == "object"]
    assert len(objects) >= 7
    loose = [where for where, s in objects if s.get("additionalProperties") is not False]
    # `plugins` maps any plugin's name to its config; each config has its plugin's schema
    assert loose == ["#/properties/plugins"]


def test_every_pattern_has_a_hint() -> None:
    missing = [
        where for where, s in subschemas(load_schema()) if "pattern" in s and "x-hint" not in s
    ]
    assert missing == []


def test_every_default_is_valid_for_its_own_schema() -> None:
    schema = load_schema()
    checked = 0
    for where, sub in subschemas(schema):
        if "default" in sub:
            resolved = {**sub, "$defs": schema["$defs"]}
            errors = list(Draft202012Validator(resolved).iter_errors(sub["default"]))
            assert errors == [], where
            checked += 1
    assert checked >= 20


# every default of `physics`, written out (not read from the schema under test)
PHYSICS_DEFAULTS = {
    "fps": 60,
    "substeps": 8,
    "gravity": [0, 0, -9.81],
    "ground_friction": 0.4,
    "sucker_timeconst": 0.005,
    "max_speed": 12,
    "max_penetration": 0.05,
    "sleep": True,
    "lod": {"enabled": True, "full": 8, "reduced": 128, "hold_seconds": 1.0, "contact_margin": 0.1},
    "separate_overlaps": False,
}


def test_with_defaults_fills_nested_defaults_exactly() -> None:
    data = {
        "version": 1,
        "creatures": [
            {"goals": [{"position": [1, 2]}], "tentacles": {"overrides": [{"index": 1}]}}
        ],
    }
    original = copy.deepcopy(data)
    full = with_defaults(data)
    assert data == original
    assert full == {
        "version": 1,
        "seed": 0,
        "physics": PHYSICS_DEFAULTS,
        "systems": [],
        "threats": [],
        "creatures": [
            {
                "name": "creature_0",
                "position": [0, 0],
                "heading_deg": 0,
                "mantle": {"radius": 0.15, "height": 0.2, "density": 400},
                "tentacles": {
                    "count": 8,
                    "links": 10,
                    "link_length": 0.07,
                    "link_radius": 0.025,
                    "end_scale": 0.3,
                    "density": 1000,
                    "strength": 25.0,
                    "damping": 0.5,
                    "max_torque": 20.0,
                    "joint_limit_deg": 60,
                    "twist": False,
                    "suckers": "tip",
                    "overrides": [{"index": 1}],
                    "speed": 1.0,
                    "target_angle_deg": 50,
                    "wave_amplitude_deg": 6,
                    "wave_frequency": 0.6,
                    "wavelength": 0.7,
                    "writhe": 0.3,
                },
                "goals": [{"position": [1, 2], "radius": 0.3}],
                "locomotion": {
                    "gait": "coordinated",
                    "speed": 1.0,
                    "drivers": 2,
                    "release_stretch": 0.04,
                    "release_reach": 1.1,
                },
                "threat": False,
            }
        ],
    }


def test_with_defaults_keeps_given_values_and_names() -> None:
    data = {
        "version": 1,
        "creatures": [{"name": "octo"}, {"tentacles": {"end_scale": 0.5}}],
        "physics": {"substeps": 2},
    }
    full = with_defaults(data)
    assert [c["name"] for c in full["creatures"]] == ["octo", "creature_1"]
    assert full["creatures"][1]["tentacles"]["end_scale"] == 0.5
    assert full["creatures"][0]["tentacles"]["end_scale"] == 0.3
    assert full["creatures"][0]["tentacles"]["overrides"] == []
    assert full["physics"] == {**PHYSICS_DEFAULTS, "substeps": 2}


def test_with_defaults_copies_defaults() -> None:
    first = with_defaults({"version": 1})
    first["physics"]["gravity"].append(1)
    first["creatures"].append({})
    assert with_defaults({"version": 1})["physics"]["gravity"] == [0, 0, -9.81]
    assert with_defaults({"version": 1})["creatures"] == []


def test_with_defaults_result_is_valid() -> None:
    full = with_defaults({"version": 1, "creatures": [{}, {"position": [1, 0]}]})
    assert validate_scene(full) == []
    assert with_defaults(full) == full


def test_the_bundled_scene_schema_is_the_assembled_default_one() -> None:
    """`scene.schema.json` (what the bundled scenes' "$schema" names, for editors) is
    `ecs-tentacles schema`'s output: the core plus the default plugins' fragments."""
    import importlib.resources

    folder = importlib.resources.files("ecs_tentacles.assets") / "schema"
    written = json.loads((folder / "scene.schema.json").read_text(encoding="utf-8"))
    assert written == load_schema(), (
        "regenerate: ecs-tentacles schema > assets/schema/scene.schema.json"
    )
