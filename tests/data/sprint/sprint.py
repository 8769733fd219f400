"""sprint: the first creature inside the finish ring wins; none by `seconds`, all lose."""

import numpy as np

from ecs_tentacles.game.modes import LOST, PLAYING, WON, GameMode, GameModes, GameResult
from ecs_tentacles.game.rules import rules
from ecs_tentacles.plugin import Plugin

RULES = {  # the mode's keys of the scene's `game` ("mode" is added)
    "required": ["finish", "seconds"],
    "properties": {
        "finish": {"type": "array", "items": {"type": "number"}, "minItems": 2, "maxItems": 2},
        "radius": {"type": "number", "minimum": 0.1, "maximum": 10, "default": 0.4},
        "seconds": {"type": "number", "minimum": 1, "maximum": 3600},
    },
}


def result(world):
    """The game now: won once a mantle is inside the ring, lost when the time is up."""
    game = rules(world.scene, SPRINT)  # the scene's `game`, the mode's defaults filled in
    creatures = world.creatures  # one row per creature: entity, mantle_row, ...
    mantles = world.transforms.pos[creatures.mantle_row, :2]
    there = np.hypot(*(mantles - game["finish"]).T) < game["radius"]
    if there.any():
        first = world.creature_name(int(creatures.entity[there][0]))
        return GameResult(WON, world.time, details={"first": first}, text=f"{first} first")
    return GameResult(LOST if world.time >= game["seconds"] else PLAYING, world.time)


SPRINT = GameMode("sprint", RULES, result)


class Sprint(Plugin):
    name = "sprint"
    description = "the first creature inside the finish ring wins"
    requires = ("locomotion", "game")  # the game layer is turned on with it

    def build(self, app):
        app.add(GameModes, SPRINT)
