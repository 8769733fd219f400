"""The herding mode's keys of the scene's `game` (`herding/herding.schema.json` beside this
module, `game_mode`): the schema the game layer checks a `"mode": "herding"` level
against (`ecs_tentacles.game`, which owns the `game` key and adds `mode`).

    "game": {"mode": "herding", "level": "Open field",
             "pen": {"centre": [3.0, 0.0], "radius": 1.2},
             "need": 4, "seconds": 60,
             "predator": {"position": [-3.0, 0.0], "speed": 0.8, "reach": 1.5}}

`need` creatures must enter the pen (a disc on the ground) within `seconds` of game
time; the predator starts at `position` and moves toward where the player aims it at
up to `speed` m/s walking (`run_speed` running, on its stamina); creatures within `reach`
(`run_reach` running) flee it. The pen has a fence and a `gate`; `par` and `herd` tune
the stars and the creatures' flocking (`herding.schema.json` says each key).
Rules the schema cannot say (`problems`): `need` at most the scene's creatures, the
predator not starting inside the pen, the gate no wider than the pen.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from ecs_tentacles.plugin import Problem
from ecs_tentacles.scene.schema import fragment

GAME = fragment("ecs_tentacles.herding", "herding")["game_mode"]["game"]


def plugin_problems(scene: Mapping[str, object]) -> list[Problem]:
    """A scene with the herding plugin on is a level: it has a `game` (its mode and the
    mode's keys are the game layer's to check: `game_problems`)."""
    game = scene.get("game")
    if game is None:
        return [(("game",), "required when the herding plugin is on (the level's rules)")]
    return []


def game_problems(scene: Mapping[str, object]) -> list[Problem]:
    """What the schema cannot say about a herding level's `game` (defaults filled)."""
    game, listed = scene["game"], scene.get("creatures") or []
    if not isinstance(game, Mapping) or not isinstance(listed, list):
        raise TypeError("a herding level's game and creatures are filled in by the validator")
    found: list[Problem] = []
    creatures = len(listed)
    if game["need"] > creatures:
        found.append(
            (("game", "need"), f"{game['need']} is more than the scene's {creatures} creatures")
        )
    pen = game["pen"]
    start = (game.get("predator") or {}).get("position", [0.0, -3.0])
    if np.hypot(*np.subtract(start, pen["centre"])) < pen["radius"]:
        found.append((("game", "predator", "position"), "inside the pen: start it outside"))
    gate = (pen.get("gate") or {}).get("width", 0.0)
    if gate > 2 * pen["radius"]:
        found.append((("game", "pen", "gate", "width"), f"{gate} is wider than the pen"))
    return found
