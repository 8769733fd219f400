"""The creator's limits: the scene schema's ranges and defaults, and `DesignError`.

The design checks every value against the same schema the scene loader uses, so a
design that accepts a value exports a scene that validates.
"""

from __future__ import annotations

import math
from typing import Any

from ecs_tentacles.scene.validate import load_schema


class DesignError(ValueError):
    """A value the design cannot take; `field` names it (`links`, `mantle_radius`...)."""

    def __init__(self, field: str, message: str):
        self.field = field
        self.message = message
        super().__init__(f"{field}: {message}")


def field_schema(section: str, key: str) -> dict[str, Any]:
    """The schema of a creature's `mantle.<key>` or `tentacles.<key>`."""
    creature = load_schema()["$defs"]["creature"]["properties"]
    found: dict[str, Any] = creature[section]["properties"][key]
    return found


def checked(field: str, section: str, key: str, value: Any) -> Any:
    """`value` if the schema allows it for `section.key`, else DesignError naming `field`."""
    spec = field_schema(section, key)
    integer = spec.get("type") == "integer"
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise DesignError(field, f"must be a number, got {value!r}")
    if not math.isfinite(value):
        raise DesignError(field, f"must be a finite number, got {value!r}")
    if integer and value != int(value):
        raise DesignError(field, f"must be a whole number, got {value!r}")
    low = spec.get("exclusiveMinimum", spec.get("minimum"))
    high = spec.get("exclusiveMaximum", spec.get("maximum"))
    too_low = low is not None and (value <= low if "exclusiveMinimum" in spec else value < low)
    too_high = high is not None and (value >= high if "exclusiveMaximum" in spec else value > high)
    if too_low or too_high:
        opening = "(" if "exclusiveMinimum" in spec else "["
        closing = ")" if "exclusiveMaximum" in spec else "]"
        raise DesignError(field, f"must be in {opening}{low}, {high}{closing}, got {value}")
    return int(value) if integer else float(value)


def default(section: str, key: str) -> Any:
    """The schema default of a creature's `mantle.<key>` or `tentacles.<key>`."""
    return field_schema(section, key)["default"]
