"""predator: the herding game's predator moves toward where the player aims it.

Each frame the predator goes straight toward `HerdingGame.state.aim`, at most `speed`
metres a second, and stops on it. It is a danger (the plugin's `Dangers` entry), so
it moves where the threats plugin's threats move (stage animate, the `DANGERS_MOVED`
phase): fur's fear sees it where it is this frame, whatever flees decides from there
in the next.

Reads: `HerdingGame` (aim, speed). Writes: `HerdingGame.state.predator`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.behaviour import DANGERS_MOVED
from ecs_tentacles.herding.game import HerdingGame
from ecs_tentacles.system import System

if TYPE_CHECKING:
    from ecs_tentacles.host import Host


class Predator(System):
    """Moves the predator toward the aim, `speed` m/s at most."""

    name = "herding_predator"
    stage = "animate"
    sets = (DANGERS_MOVED,)
    reads = ()
    writes = ()

    def process(self, world: Host, dt: float) -> None:
        game = world.resource(HerdingGame)
        state = game.state
        to_aim = state.aim - state.predator
        distance = float(np.hypot(*to_aim))
        step = game.speed * dt
        if distance <= step:
            state.predator = state.aim.copy()
        else:
            state.predator = state.predator + to_aim * (step / distance)
