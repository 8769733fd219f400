"""Field ranges come from the schema, and every run-time setter uses them."""

from __future__ import annotations

import math

import numpy as np
import pytest

from ecs_tentacles.creator.limits import DesignError, checked
from ecs_tentacles.locomotion.params import settable
from ecs_tentacles.scene.ranges import Range, field_range, physics_range
from ecs_tentacles.scene.schema import load_schema


def test_ranges_are_the_schemas() -> None:
    assert field_range("tentacles", "strength") == Range(0, 1000)
    assert field_range("tentacles", "speed") == Range(0.01, 10)
    assert field_range("tentacles", "end_scale") == Range(0, 1, low_open=True)
    assert field_range("tentacles", "links") == Range(1, 64, integer=True)
    assert field_range("mantle", "radius") == Range(5e-5, 10)
    assert physics_range("gravity") == Range(-30, 30)
    assert physics_range("fps") == Range(4, 1000)
    assert physics_range("substeps") == Range(1, 100, integer=True)
    assert field_range("locomotion", "drivers").high == 16


def test_a_missing_bound_is_infinite() -> None:
    schema = load_schema()["properties"]["seed"]
    assert "maximum" not in schema
    assert str(Range(0, math.inf)) == "[0, inf]"


@pytest.mark.parametrize(
    ("value", "message"),
    [
        (5e4, "strength: must be in [0, 1000], got 50000.0"),
        (-1, "strength: must be in [0, 1000], got -1"),
        (float("nan"), "strength: must be a finite number, got nan"),
        ("12", "strength: must be a number, got '12'"),
        (True, "strength: must be a number, got True"),
    ],
)
def test_check_names_the_field(value: object, message: str) -> None:
    with pytest.raises(ValueError) as refused:
        field_range("tentacles", "strength").check("strength", value)
    assert str(refused.value) == message


def test_check_keeps_whole_numbers_whole() -> None:
    links = field_range("tentacles", "links")
    assert links.check("links", 4.0) == 4 and isinstance(links.check("links", 4.0), int)
    with pytest.raises(ValueError, match=r"^links: must be a whole number, got 2.5$"):
        links.check("links", 2.5)
    assert field_range("tentacles", "speed").check("speed", np.float32(2)) == 2.0


def test_the_locomotion_api_uses_the_schema_ranges_in_radians() -> None:
    api_ranges = {name: p.range for name, p in settable()[0].items()}
    assert set(api_ranges) == {
        "speed",
        "target_angle",
        "strength",
        "damping",
        "wave_amplitude",
        "wave_frequency",
        "wavelength",
        "writhe",
    }
    assert api_ranges["strength"] == field_range("tentacles", "strength")
    assert api_ranges["wave_amplitude"] == Range(0, math.radians(60))
    assert api_ranges["target_angle"].high == pytest.approx(math.pi / 2)
    for name, allowed in api_ranges.items():
        key = {"target_angle": "target_angle_deg", "wave_amplitude": "wave_amplitude_deg"}
        scene_range = field_range("tentacles", key.get(name, name))
        factor = math.radians(1) if name in key else 1.0
        assert allowed == scene_range.scaled(factor), name


def test_the_creator_refuses_what_the_schema_refuses() -> None:
    with pytest.raises(DesignError) as refused:
        checked("link_length", "tentacles", "link_length", 0.0)
    assert refused.value.field == "link_length"
    assert refused.value.message == "must be in [1e-06, 10], got 0.0"
    assert checked("count", "tentacles", "count", 3.0) == 3


def test_an_unknown_field_is_named() -> None:
    with pytest.raises(KeyError, match=r"tentacles\.colour: not a field of the scene schema"):
        field_range("tentacles", "colour")
