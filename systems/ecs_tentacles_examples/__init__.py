"""Example plugins (not on by default): wander, flee, follow_leader, flock.

Written as a user writes a plugin: a package of its own beside the engine, importing only
the engine's public modules, registered by entry points (`ecs_tentacles.plugins` in
pyproject.toml) as any installed plugin is; a scene turns one on by name under `plugins`.
Each is one file: a `Plugin` and the stage-`decide` `System` it brings, which sends
creatures somewhere (`ecs_tentacles.behaviour.travel`: the locomotion plugin's goals,
though no example names it) every `interval` seconds rather than every frame, so
strokes can finish. What they share is here: a number setting, the two re-planning
settings, the check that a goal set some distance away is not reached at once, the config
schema's frame (`settings`), sending creatures to their goals (`send_goals`) and the
columns sending a creature writes (`ecs_tentacles.behaviour.DESTINATION_WRITES`, what
each system declares).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

import numpy as np

from ecs_tentacles.behaviour import DESTINATION_WRITES, travel
from ecs_tentacles.plugin import Plugin, Problem
from ecs_tentacles.scene.defaults import plugin_config

if TYPE_CHECKING:
    from ecs_tentacles.host import Host

# the store columns sending a creature writes: `ecs_tentacles.behaviour`'s (named here
# too, for code that imported it from the examples)
__all__ = [
    "DESTINATION_WRITES",
    "Problem",
    "farther_than_reach",
    "number",
    "replanning",
    "send_goals",
    "settings",
]


def number(low: float, high: float, default: float, description: str) -> dict[str, Any]:
    """The schema of a number setting in [low, high]."""
    return {
        "type": "number",
        "minimum": low,
        "maximum": high,
        "default": default,
        "description": description,
    }


def settings(**properties: dict[str, Any]) -> dict[str, Any]:
    """A plugin's config schema: an object of these `properties` and no others."""
    return {"type": "object", "additionalProperties": False, "properties": properties}


def replanning(interval: float) -> dict[str, dict[str, Any]]:
    """`interval` (seconds between re-plans, default `interval`) and `goal_radius`."""
    return {
        "interval": number(0.05, 600, interval, "Seconds between re-plans."),
        "goal_radius": number(0.05, 5, 0.3, "Metres: a goal it sets is reached within this."),
    }


def farther_than_reach(
    plugin: Plugin, scene: Mapping[str, Any], key: str, times: float = 1.0
) -> list[Problem]:
    """A problem unless the config's `key` is more than `times` x its `goal_radius`.

    Else the goals it sets would be reached where the creature stands.
    """
    config = plugin_config(plugin, scene.get("plugins", {}).get(plugin.key))
    reach = times * config["goal_radius"]
    if config[key] > reach:
        return []
    factor = "" if times == 1 else f"{times:g} x "
    message = f"must be > {factor}goal_radius ({reach:g}), got {config[key]:g}"
    return [(("plugins", plugin.key, key), message)]


def send_goals(world: Host, rows: np.ndarray, goals: np.ndarray, goal_radius: float) -> None:
    """Send the creatures at CreatureStore `rows` to `goals` ((n, 2) metres), each reached
    within `goal_radius` (`ecs_tentacles.behaviour.travel`)."""
    entities = world.creatures.entity[rows]
    for entity, goal in zip(entities, goals, strict=True):
        travel(world).send(world, int(entity), goal, goal_radius)
