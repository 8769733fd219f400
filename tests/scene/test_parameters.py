"""The parameter table: read from the schema's annotations, and driving build and the API."""

from __future__ import annotations

import copy
import math
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from ecs_tentacles.locomotion.params import Locomotion, settable
from ecs_tentacles.scene.parameters import (
    Parameter,
    apply_parameters,
    parameter,
    parameters,
    read_parameters,
)
from ecs_tentacles.scene.ranges import Range
from ecs_tentacles.scene.schema import load_schema
from ecs_tentacles.world import World
from tests.conftest import creature_scene


def _annotated(node: Any, column: str) -> list[dict[str, Any]]:
    """Every property of the raw schema JSON annotated with `column` (no table code)."""
    if isinstance(node, list):
        return [found for item in node for found in _annotated(item, column)]
    if not isinstance(node, dict):
        return []
    here = [node] if node.get("x-parameter", {}).get("column") == column else []
    return here + [found for value in node.values() for found in _annotated(value, column)]


def test_strength_is_defined_once_and_the_table_reads_it() -> None:
    (spec,) = _annotated(load_schema(), "motors.strength")
    strength = parameter("tentacles", "strength")
    assert (strength.store, strength.field, strength.api) == ("motors", "strength", "strength")
    assert strength.range == Range(spec["minimum"], spec["maximum"])
    assert (strength.units, strength.label, strength.taper) == ("N m/rad", "strength (kp)", "scale")
    assert strength.runtime and strength.factor == 1.0


def test_degree_keys_are_radians_in_code() -> None:
    angle = parameter("tentacles", "target_angle_deg")
    assert (angle.api, angle.units, angle.column) == (
        "target_angle",
        "deg",
        "locomotion.tentacles.target_angle",
    )
    assert angle.range == Range(0, math.radians(90))
    assert angle.from_scene(45) == pytest.approx(math.radians(45), rel=1e-15)


def test_every_column_exists_on_a_world(make_world: Callable[..., World]) -> None:
    world = make_world(creature_scene(count=2, links=3))
    for p in parameters():
        store = world.stores[p.store]
        for field in (p.field, p.taper):
            if field is not None:
                assert len(getattr(store, field)) == len(store), (p.key, field)
        if p.at_most is not None:  # a cap from another store lines up row for row
            assert len(p.cap(world)) == len(store), (p.key, p.at_most)


def test_gait_is_encoded_once_as_the_schemas_choice_index() -> None:
    gait = parameter("locomotion", "gait")
    (spec,) = _annotated(load_schema(), "locomotion.creatures.gait")
    assert gait.choices == tuple(spec["enum"]) == ("cyclic", "coordinated")
    assert [gait.code(g) for g in gait.choices] == [0, 1]
    assert gait.to_api(1) == "coordinated"


def test_build_fills_columns_from_the_scene_tapered_and_in_radians(
    make_world: Callable[..., World],
) -> None:
    scene = creature_scene(
        count=3,
        links=4,
        strength=30.0,
        max_torque=12.0,
        target_angle_deg=40,
        overrides=[{"index": 1, "strength": 45.0, "wave_amplitude_deg": 20}],
    )
    scene["creatures"][0]["locomotion"] = {"gait": "cyclic", "drivers": 9, "speed": 1.5}
    world = make_world(scene)
    scale = world.motors.scale
    assert_allclose(scale[:4], [1.0, 1 - 0.7 / 3, 1 - 1.4 / 3, 0.3])  # end_scale 0.3 default
    assert_array_equal(world.motors.strength[:4], 30.0 * scale[:4])
    assert_array_equal(world.motors.strength[4:8], 45.0 * scale[4:8])
    assert_array_equal(world.motors.max_torque[:12], 12.0 * scale[:12])
    assert_array_equal(world.stores["locomotion.tentacles"].target_angle, np.radians([40, 40, 40]))
    assert_array_equal(world.stores["locomotion.tentacles"].wave_amplitude, np.radians([6, 20, 6]))
    assert world.tentacles.joint_limit[0] == pytest.approx(math.radians(60))
    assert world.stores["locomotion.creatures"].gait[0] == parameter("locomotion", "gait").code(
        "cyclic"
    )
    assert (
        world.stores["locomotion.creatures"].drivers[0] == 3
    )  # at most the tentacle count (`at_most`)
    assert world.stores["locomotion.creatures"].speed[0] == 1.5


def test_the_api_takes_each_parameter_over_its_table_range(
    make_world: Callable[..., World],
) -> None:
    world = make_world(creature_scene(count=2, links=3, damping=10.0))
    octo = world.creature("octo")
    per_tentacle, per_creature = settable()
    assert set(per_creature) == {"gait", "speed", "drivers"}
    for name, p in per_tentacle.items():
        assert p.range is not None
        world.resource(Locomotion).set(octo, tentacle=1, **{name: p.range.high})
        assert world.resource(Locomotion).get(octo, 1)[name] == pytest.approx(p.range.high)
        with pytest.raises(ValueError, match=rf"^{name}: must be in \[.*, got"):
            world.resource(Locomotion).set(octo, **{name: p.range.high * 1.01 + 1e-9})
    world.resource(Locomotion).set(octo, tentacle=1, target_angle=math.radians(30))
    assert world.stores["locomotion.tentacles"].target_angle[1] == pytest.approx(math.radians(30))
    first = int(world.tentacles.first_link[1])
    world.resource(Locomotion).set(octo, tentacle=1, strength=20.0)
    assert_allclose(world.motors.strength[first : first + 3], 20.0 * world.motors.scale[:3])


def test_a_plugin_fragment_anywhere_in_the_schema_is_found() -> None:
    """The lead moves `locomotion` into a plugin fragment: the reader walks, not paths."""
    schema = copy.deepcopy(load_schema())
    creature = schema["$defs"]["creature"]["properties"]
    fragment = creature.pop("locomotion")
    schema["properties"]["plugins"] = {
        "type": "object",
        "properties": {"crawl": {"type": "object", "allOf": [{"properties": {}}]}},
    }
    schema["properties"]["plugins"]["properties"]["crawl"]["allOf"][0]["properties"] = {
        "locomotion": fragment
    }
    moved = read_parameters(schema)
    assert sorted(moved, key=str) == sorted(parameters(), key=str)
    assert parameter("locomotion", "drivers", moved) == parameter("locomotion", "drivers")


def test_apply_parameters_writes_only_its_section_and_stores(
    make_world: Callable[..., World],
) -> None:
    world = make_world(creature_scene(count=2, links=3))
    strokes, gaits = world.stores["locomotion.tentacles"], world.stores["locomotion.creatures"]
    before = strokes.speed.copy()
    apply_parameters(world, "locomotion", {"speed": 2.5, "drivers": 5}, {"locomotion.creatures": 0})
    assert gaits.speed[0] == 2.5 and gaits.drivers[0] == 2
    assert_array_equal(strokes.speed, before)  # tentacles.speed: another section
    apply_parameters(world, "tentacles", {"damping": 3.0, "speed": 0.5}, {"motors": [3, 4]})
    assert_array_equal(world.motors.damping[3:5], 3.0 * world.motors.scale[3:5])
    assert_array_equal(strokes.speed, before)  # no locomotion.tentacles rows given


def _with(annotation: dict[str, Any], key: str = "colour") -> dict[str, Any]:
    schema = copy.deepcopy(load_schema())
    tentacles = schema["$defs"]["creature"]["properties"]["tentacles"]["properties"]
    tentacles[key] = {"type": "number", "minimum": 0, "x-parameter": annotation}
    return schema


@pytest.mark.parametrize(
    ("annotation", "key", "message"),
    [
        (
            {"column": "motors.strength", "units": "", "label": "again"},
            "colour",
            r"tentacles\.properties\.colour: column motors\.strength is already"
            r" defined at .*tentacles\.properties\.strength$",
        ),
        (
            {"column": "tentacles.hue", "units": "", "label": "hue", "colour": 1},
            "colour",
            r"colour\.x-parameter: unknown key 'colour'$",
        ),
        ({"column": "hue", "units": "", "label": "hue"}, "colour", r"<store>\.<field>, got 'hue'"),
        (
            {"column": "tentacles.hue", "units": "rad", "label": "hue"},
            "hue_deg",
            r"hue_deg\.x-parameter: units must be 'deg' exactly when the key ends in _deg$",
        ),
        ({"column": "tentacles.hue", "label": "hue"}, "colour", r"needs column, units, label$"),
    ],
)
def test_a_bad_annotation_names_its_schema_path(
    annotation: dict[str, Any], key: str, message: str
) -> None:
    with pytest.raises(ValueError, match=message):
        read_parameters(_with(annotation, key))


def test_tentacle_overrides_allow_exactly_the_parameters_range() -> None:
    """Overrides repeat the ranges (a `$ref` would also fill their defaults): keep them equal."""
    override = load_schema()["$defs"]["tentacle_override"]["properties"]
    shared = [p for p in parameters() if p.section == "tentacles" and p.key in override]
    assert {p.key for p in shared} >= {"strength", "damping", "speed", "target_angle_deg"}
    for p in shared:
        (spec,) = _annotated(load_schema(), p.column)
        bounds = ("minimum", "maximum", "exclusiveMinimum", "exclusiveMaximum")
        assert {k: override[p.key].get(k) for k in bounds} == {k: spec.get(k) for k in bounds}


def test_parameter_of_an_unknown_key_says_so() -> None:
    with pytest.raises(KeyError, match=r"tentacles\.colour: not a parameter"):
        parameter("tentacles", "colour")
    assert isinstance(parameter("locomotion", "speed"), Parameter)
