"""Numeric ranges of scene fields, read from the scene schema: the one place they live.

The loader validates scenes against the schema; the run-time setters
(`world.resource(Locomotion).set`), the HUD sliders and the creature creator check values with
the same ranges through this module, so nothing can be set at run time that a scene
could not say.

    field_range("tentacles", "strength")          # Range(low=0, high=1000, ...)
    field_range("tentacles", "strength").check("strength", 5e4)   # ValueError
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, replace
from typing import Any

from ecs_tentacles.scene.schema import at, core_schema, load_schema

JsonPath = tuple[str | int, ...]
SchemaObject = tuple[str, Mapping[str, object], JsonPath]
# schema keywords that hold subschemas, by name, one, or a list (the walk follows these)
_BY_NAME = ("properties", "$defs", "patternProperties", "dependentSchemas")
_NESTED = ("items", "additionalProperties", "not", "if", "then", "else", "contains")
_LISTS = ("allOf", "anyOf", "oneOf", "prefixItems")


@dataclass(frozen=True)
class Range:
    """An interval of allowed numbers; `integer` ranges take whole numbers only."""

    low: float
    high: float
    low_open: bool = False
    high_open: bool = False
    integer: bool = False

    def __str__(self) -> str:
        """`[0, 1000]`, `(0, 10]`: numbers shortened with `g`."""
        opening, closing = "(" if self.low_open else "[", ")" if self.high_open else "]"
        return f"{opening}{self.low:g}, {self.high:g}{closing}"

    def __contains__(self, value: object) -> bool:
        if not isinstance(value, int | float):
            return False
        above = value > self.low if self.low_open else value >= self.low
        below = value < self.high if self.high_open else value <= self.high
        return above and below

    def scaled(self, factor: float) -> Range:
        """The same range in other units (degrees in the scene, radians in the API)."""
        return replace(self, low=self.low * factor, high=self.high * factor)

    def check(self, name: str, value: object) -> float:
        """`value` (a float, or an int for integer ranges) if allowed, else a ValueError."""
        if isinstance(value, bool) or not isinstance(value, numbers.Real):
            raise ValueError(f"{name}: must be a number, got {value!r}")
        value = float(value) if not isinstance(value, int) else value
        if not math.isfinite(value):
            raise ValueError(f"{name}: must be a finite number, got {value!r}")
        if self.integer and value != int(value):
            raise ValueError(f"{name}: must be a whole number, got {value!r}")
        if value not in self:
            raise ValueError(f"{name}: must be in {self}, got {value!r}")
        return int(value) if self.integer else float(value)


def schema_range(spec: Mapping[str, object]) -> Range:
    """The range a number property of the schema allows (`minimum`, `exclusiveMaximum`...)."""
    low_open, high_open = "exclusiveMinimum" in spec, "exclusiveMaximum" in spec
    low = spec.get("exclusiveMinimum", spec.get("minimum", -math.inf))
    high = spec.get("exclusiveMaximum", spec.get("maximum", math.inf))
    if not isinstance(low, int | float) or not isinstance(high, int | float):
        raise ValueError(f"a range's bounds are numbers, got {low!r} and {high!r}")
    return Range(low, high, low_open, high_open, spec.get("type") == "integer")


def schema_objects(node: object, name: str = "", path: JsonPath = ()) -> Iterator[SchemaObject]:
    """(name, object schema, JSON path) of every object schema with `properties` in `node`.

    An object is named by the property or definition holding it (`tentacles`,
    `locomotion`), so a field is found wherever a schema (the bundled one, or one
    assembled from plugins' fragments) puts it; array items keep their holder's name.
    """
    if not isinstance(node, Mapping):
        return
    if isinstance(node.get("properties"), Mapping):
        yield name, node, path
    for keyword in _BY_NAME:
        for child_name, child in (node.get(keyword) or {}).items():
            yield from schema_objects(child, child_name, (*path, keyword, child_name))
    for keyword in _NESTED:
        yield from schema_objects(node.get(keyword), name, (*path, keyword))
    for keyword in _LISTS:
        for i, child in enumerate(node.get(keyword) or []):
            yield from schema_objects(child, name, (*path, keyword, i))


def field_schema(section: str, key: str) -> dict[str, Any]:
    """The schema of `<section>.<key>` (section: mantle, tentacles, locomotion...)."""
    for name, node, _ in schema_objects(load_schema()):  # the default plugins' fields too
        properties = node["properties"]
        found = properties.get(key) if isinstance(properties, Mapping) else None
        if name == section and isinstance(found, dict):
            return found
    raise KeyError(f"{section}.{key}: not a field of the scene schema")


def field_range(section: str, key: str) -> Range:
    """The range of a creature's `<section>.<key>`, e.g. `("tentacles", "strength")`."""
    return schema_range(field_schema(section, key))


def physics_range(key: str) -> Range:
    """The range of the scene's `physics.<key>` (for gravity: of each component)."""
    spec = at(core_schema(), "properties", "physics", "properties", key)
    items = spec.get("items")
    return schema_range(items if isinstance(items, Mapping) else spec)


def damping_floor(strength: float, step: float) -> float:
    """The least servo damping (N m s / rad) that keeps a servo of `strength` stable.

    MuJoCo integrates the damping implicitly and the stiffness explicitly: one physics
    step of `step` seconds stays stable, whatever the link's inertia, while
    `strength * step**2 < 2 * damping * step` (+ 4 x inertia). Asking for
    `damping >= strength * step` keeps a factor of two; undamped stiff servos (damping 0,
    strength 100) shook their links apart at 60 fps.
    """
    return float(strength) * float(step)
