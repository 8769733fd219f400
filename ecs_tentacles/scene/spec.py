"""`CreatureSpec`: one creature's scene entry, validated, with its defaults filled in.

The one type a creature's entry has from validation through loading, spawning and
building (`ecs_tentacles.creatures`), saving (`roster_save`) and `world.creature_specs`.
Core's keys are typed; the keys plugins add (goals, fur, emotion ...) are the plugins'
own: core never reads them, and a plugin's hooks see the entry as a
`Mapping[str, Any]` (`Plugin.build_creature`), so a feature reads its keys there.

    for spec in creature_specs(scene):           # list[CreatureSpec]
        layout = creature_layout(spec, ground)    # worked out once per creature
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, TypedDict, cast


class CreatureSpec(TypedDict, total=False):
    """A creature's scene entry (`assets/schema/core.schema.json`'s creature), defaults in."""

    name: str
    position: list[float]  # x, y (resting on the ground) or x, y, z of the mantle's base
    heading_deg: float
    mantle: dict[str, Any]  # radius, height, density
    tentacles: dict[str, Any]  # count, links, link_length, ... and per-tentacle overrides


def creature_specs(scene: Mapping[str, Any]) -> list[CreatureSpec]:
    """The creatures of a validated scene (defaults filled in), as specs."""
    return cast("list[CreatureSpec]", list(scene["creatures"]))


def as_spec(entry: Mapping[str, Any]) -> CreatureSpec:
    """A validated creature entry as a spec (the validator made it one)."""
    return cast("CreatureSpec", entry)
