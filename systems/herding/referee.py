"""referee: the herding game's clock, pen and outcome.

While the game is played, each frame adds one to the clock and every creature whose
mantle is inside the pen for the first time is penned (it stays counted if it walks
out again). When `need` creatures are penned the game is won (`GameWon`); when the
clock reaches `seconds` first it is lost (`GameLost`). Either way the clock stops.

Reads: `HerdingGame`, CreatureStore (entity, mantle_row), Transform store (pos).
Writes: `HerdingGame.state` (frames, penned, outcome); events `CreaturePenned`,
`GameWon`, `GameLost`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.herding.events import CreaturePenned, GameLost, GameWon
from ecs_tentacles.herding.game import LOST, PLAYING, WON, HerdingGame
from ecs_tentacles.system import System

if TYPE_CHECKING:
    from ecs_tentacles.host import Host


class Referee(System):
    """Pens creatures, runs the clock, and ends the game."""

    name = "herding_referee"
    stage = "output"
    reads = ("transforms.pos", "creatures.entity", "creatures.mantle_row")
    writes = ()

    def process(self, world: Host, dt: float) -> None:
        game = world.resource(HerdingGame)
        state = game.state
        if state.outcome != PLAYING:
            return
        state.frames += 1
        creatures = world.creatures
        mantles = world.transforms.pos[creatures.mantle_row]
        inside = game.in_pen(mantles[:, :2])
        arrived = inside & ~np.isin(creatures.entity, state.penned)  # in for the first time
        for row in np.flatnonzero(arrived).tolist():
            entity = int(creatures.entity[row])
            state.penned.append(entity)
            x, y, z = (float(v) for v in mantles[row])
            state.penned_at.append((x, y, z))
            world.events.emit(CreaturePenned(world, entity, game.elapsed, len(state.penned)))
        if len(state.penned) >= game.need:
            state.outcome = WON
            world.events.emit(GameWon(world, game.elapsed, len(state.penned)))
        elif state.frames >= round(game.seconds * game.fps):
            state.outcome = LOST
            world.events.emit(GameLost(world, game.elapsed, len(state.penned), game.need))
