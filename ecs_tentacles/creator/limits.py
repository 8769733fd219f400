"""The creator's limits: the scene schema's ranges, defaults and sliders, `DesignError`.

The design checks every value against the same schema the scene loader uses (through
`ecs_tentacles.scene.ranges`), so a design that accepts a value exports a scene that
validates.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from ecs_tentacles.scene.ranges import field_range, field_schema


class DesignError(ValueError):
    """A value the design cannot take; `field` names it (`links`, `mantle_radius`...)."""

    def __init__(self, field: str, message: str):
        self.field = field
        self.message = message
        super().__init__(f"{field}: {message}")


def checked(field: str, section: str, key: str, value: object) -> Any:
    """`value` if the schema allows it for `section.key`, else DesignError naming `field`."""
    try:
        return field_range(section, key).check(field, value)
    except ValueError as error:
        raise DesignError(field, str(error).removeprefix(f"{field}: ")) from None


@dataclass(frozen=True)
class Setting:
    """A creator slider: which design value it edits, its label, its range."""

    name: str
    label: str
    low: float
    high: float
    whole: bool = False


def editor_setting(name: str, section: str, key: str, *, short: bool = False) -> Setting:
    """The slider of `section.key` as the schema's `x-editor` mark says (label, low, high).

    The slider's range is a comfortable part of the field's schema range (checked here).
    """
    spec = field_schema(section, key)
    mark = spec["x-editor"]
    allowed = field_range(section, key)
    if mark["low"] not in allowed or mark["high"] not in allowed:
        raise ValueError(f"{section}.{key}: x-editor range outside the schema's {allowed}")
    label = mark.get("short", mark["label"]) if short else mark["label"]
    return Setting(name, label, mark["low"], mark["high"], spec.get("type") == "integer")


def default(section: str, key: str) -> Any:
    """The schema default of a creature's `mantle.<key>` or `tentacles.<key>`."""
    return field_schema(section, key)["default"]
