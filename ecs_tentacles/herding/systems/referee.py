"""referee: the herding game's clock, pen and outcome.

While the game is played, each frame adds one to the clock; a creature whose mantle
comes inside the pen's fence is penned, and one driven out again (through the gate) is
no longer (`CreatureLeft`). When `need` creatures are penned the game is won (`GameWon`); when the
clock reaches `seconds` first it is lost (`GameLost`). Either way the clock stops.

Reads: `HerdingGame`, CreatureStore (entity, mantle_row), Transform store (pos).
Writes: `HerdingGame.state` (frames, penned, outcome); events `CreaturePenned`,
`CreatureLeft`, `GameWon`, `GameLost`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.game.modes import Referee as ModeReferee
from ecs_tentacles.herding.events import CreatureLeft, CreaturePenned, GameLost, GameWon
from ecs_tentacles.herding.game import LOST, WON, HerdingGame

if TYPE_CHECKING:
    from ecs_tentacles.host import Host


class Referee(ModeReferee[HerdingGame]):
    """Pens creatures, runs the clock, and ends the game."""

    name = "herding_referee"

    def played(self, world: Host) -> HerdingGame:
        return world.resource(HerdingGame)

    def judge(self, world: Host, game: HerdingGame) -> None:
        state = game.state
        creatures = world.creatures
        mantles = world.transforms.pos[creatures.mantle_row]
        inside = game.in_pen(mantles[:, :2])
        out = set(creatures.entity[~inside].tolist())
        for i in [i for i, entity in enumerate(state.penned) if entity in out]:  # driven out
            world.events.emit(CreatureLeft(world, state.penned[i], game.elapsed))
        kept = [i for i, entity in enumerate(state.penned) if entity not in out]
        state.penned = [state.penned[i] for i in kept]
        state.penned_at = [state.penned_at[i] for i in kept]
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
