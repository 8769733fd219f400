"""`CreatureSpec`: one creature's scene entry, validated, with its defaults filled in.

The one type a creature's entry has from validation through loading, spawning and
building (`ecs_tentacles.creatures`), saving (`roster_save`) and `world.creature_specs`.
Core's keys are typed down to the leaves (`MantleSpec`, `TentaclesSpec`, each
tentacle's `TentacleSettings` and `TentacleOverride`); the keys plugins add (goals,
fur, emotion, locomotion's tentacle keys ...) are the plugins' own: core never reads
them, and a plugin's hooks see the entry as a `Mapping[str, object]`
(`Plugin.build_creature`), so a feature reads its keys there.

TypedDicts, not dataclasses: an entry is JSON the validator completed (a dict), and it
stays one all the way (plugins' keys ride along, `roster_save` writes it back, a
crowd of 10,000 is not copied into objects); the types cost nothing at run time and
let mypy check every key core reads.

    for spec in creature_specs(scene):            # list[CreatureSpec]
        layout = world.layouts.on(spec, ground)    # `ecs_tentacles.scene.layouts`
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Literal, Required, TypedDict, cast


class MantleSpec(TypedDict):
    """A creature's mantle: a cylinder (metres, kg/m^3)."""

    radius: float
    height: float
    density: float


class TentacleSettings(TypedDict):
    """One tentacle's settings: the creature's `tentacles` with its override applied
    (`scene.construction.tentacle_params`; the plugins' tentacle keys ride along)."""

    count: int
    links: int
    link_length: float  # m, of the first link (the others taper by `end_scale`)
    link_radius: float  # m, of the first link
    end_scale: float
    density: float
    strength: float
    damping: float
    max_torque: float
    joint_limit_deg: float
    twist: bool
    suckers: Literal["tip", "every_link"]


class TentacleOverride(TypedDict, total=False):
    """Settings of tentacle `index` over the creature's."""

    index: Required[int]
    links: int
    link_length: float
    link_radius: float
    end_scale: float
    strength: float
    damping: float


class TentaclesSpec(TentacleSettings):
    """A creature's tentacles: the settings they share and each one's overrides."""

    overrides: list[TentacleOverride]


class CreatureSpec(TypedDict, total=False):
    """A creature's scene entry (`assets/schema/core.schema.json`'s creature), defaults in."""

    name: str
    position: list[float]  # x, y (resting on the ground) or x, y, z of the mantle's base
    heading_deg: float
    mantle: MantleSpec
    tentacles: TentaclesSpec


def creature_specs(scene: Mapping[str, object]) -> list[CreatureSpec]:
    """The creatures of a validated scene (defaults filled in), as specs."""
    creatures = scene["creatures"]
    if not isinstance(creatures, list):
        raise TypeError(f"scene.creatures: a list, not {type(creatures).__name__}")
    return cast("list[CreatureSpec]", list(creatures))


def as_spec(entry: Mapping[str, object]) -> CreatureSpec:
    """A validated creature entry as a spec (the validator made it one)."""
    return cast("CreatureSpec", entry)
