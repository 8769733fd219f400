"""The creator's limits: the scene schema's ranges and defaults, and `DesignError`.

The design checks every value against the same schema the scene loader uses (through
`ecs_tentacles.scene.ranges`), so a design that accepts a value exports a scene that
validates.
"""

from __future__ import annotations

from typing import Any

from ecs_tentacles.scene.ranges import field_range, field_schema


class DesignError(ValueError):
    """A value the design cannot take; `field` names it (`links`, `mantle_radius`...)."""

    def __init__(self, field: str, message: str):
        self.field = field
        self.message = message
        super().__init__(f"{field}: {message}")


def checked(field: str, section: str, key: str, value: Any) -> Any:
    """`value` if the schema allows it for `section.key`, else DesignError naming `field`."""
    try:
        return field_range(section, key).check(field, value)
    except ValueError as error:
        raise DesignError(field, str(error).removeprefix(f"{field}: ")) from None


def default(section: str, key: str) -> Any:
    """The schema default of a creature's `mantle.<key>` or `tentacles.<key>`."""
    return field_schema(section, key)["default"]
