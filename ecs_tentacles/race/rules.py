"""The race mode's keys of the scene's `game` (`"mode": "race"`), and what the schema
cannot say about them.

    "game": {"mode": "race", "level": "2. The wall", "runner": "you",
             "flag": {"position": [6.0, 0.0], "radius": 0.5},
             "seconds": 90, "rivals_wait": 0}

`runner` names the creature the player steers; every other creature is a rival. The
race is won when the runner's mantle is first inside the flag's ring (`radius` m round
`position`), lost when a rival's is or `seconds` of game time pass first. The rivals
set off `rivals_wait` seconds after the start (a head start for the runner).
Checks (`problems`): `runner` names a creature of the scene, and nobody starts at the
flag.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from ecs_tentacles.plugin import Problem

XY = {
    "type": "array",
    "items": {"type": "number", "minimum": -1000, "maximum": 1000},
    "minItems": 2,
    "maxItems": 2,
}
RULES: dict[str, object] = {
    "description": "A race to the flag: the runner (yours) against every other creature.",
    "required": ["runner", "flag", "seconds"],
    "properties": {
        "level": {
            "type": "string",
            "minLength": 1,
            "maxLength": 60,
            "description": "The level's name on the HUD (default: the scene's name).",
        },
        "runner": {
            "type": "string",
            "minLength": 1,
            "maxLength": 200,
            "description": "The creature the player steers (its name).",
        },
        "flag": {
            "type": "object",
            "additionalProperties": False,
            "required": ["position"],
            "properties": {
                "position": {**XY, "description": "Metres: the flag on the ground."},
                "radius": {"type": "number", "minimum": 0.2, "maximum": 5, "default": 0.5},
            },
        },
        "seconds": {"type": "number", "minimum": 5, "maximum": 3600},
        "rivals_wait": {
            "type": "number",
            "minimum": 0,
            "maximum": 600,
            "default": 0,
            "description": "Seconds after the start before the rivals set off.",
        },
    },
}


def problems(scene: Mapping[str, object]) -> list[Problem]:
    """What the schema cannot say about a race level (its `game` has its defaults)."""
    game, creatures = scene["game"], scene.get("creatures") or []
    if not isinstance(game, Mapping) or not isinstance(creatures, list):
        raise TypeError("a race level's game and creatures are filled in by the validator")
    names = [creature["name"] for creature in creatures]
    found: list[Problem] = []
    if game["runner"] not in names:
        shown = ", ".join(names[:8]) + (", ..." if len(names) > 8 else "")
        found.append((("game", "runner"), f"{game['runner']!r} is no creature here ({shown})"))
    flag, radius = np.asarray(game["flag"]["position"]), game["flag"]["radius"]
    for i, creature in enumerate(creatures):
        if np.hypot(*(np.asarray(creature["position"][:2]) - flag)) < radius:
            found.append((("creatures", i, "position"), "starts at the flag: start it away"))
    return found
