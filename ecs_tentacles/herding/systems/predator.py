"""predator: the herding game's predator moves toward where the player aims it.

Each frame the predator goes straight toward `HerdingGame.state.aim`, at most `speed`
metres a second walking (`run_speed` running), and stops on it. Running drains its
stamina (empty after `stamina_s` seconds of running); walking or standing refills it
(full after `recover_s`). Run dry, it is winded: it walks until its stamina is back
to `RECOVERED`, whatever the player asks. It is a danger (the plugin's `Dangers` entry), so
it moves where the threats plugin's threats move (stage animate, the `DANGERS_MOVED`
phase): fur's fear sees it where it is this frame, whatever flees decides from there
in the next.

Reads: `HerdingGame` (aim, speeds, running asked, stamina). Writes:
`HerdingGame.state` (predator, heading, stamina, winded).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.behaviour import DANGERS_MOVED
from ecs_tentacles.herding.game import RECOVERED, HerdingGame
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
        sprint = game.sprinting and distance > 0
        step = (game.run_speed if sprint else game.speed) * dt
        if sprint:
            state.stamina = max(0.0, state.stamina - dt / game.stamina_s)
            state.winded = state.stamina <= 0.0
        else:
            state.stamina = min(1.0, state.stamina + dt / game.recover_s)
            state.winded = state.winded and state.stamina < RECOVERED
        if distance > 1e-6:
            state.heading = float(np.arctan2(to_aim[1], to_aim[0]))
        if distance <= step:
            state.predator = state.aim.copy()
        else:
            state.predator = state.predator + to_aim * (step / distance)
