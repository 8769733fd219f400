"""referee: the race's clock and who reached the flag first.

While the race is run each frame adds one to the clock. The first creature whose mantle
is inside the flag's ring ends it: the runner wins it, a rival loses it for the player
(the runner first when both arrive in the same frame); the clock reaching `seconds`
first loses it too. Either way the clock stops and `RaceFinished` is emitted.

Reads: `RaceGame`, CreatureStore (entity, mantle_row), Transform store (pos).
Writes: `RaceGame.state` (frames, outcome, winner); event `RaceFinished`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.game.modes import LOST, WON
from ecs_tentacles.game.modes import Referee as ModeReferee
from ecs_tentacles.race.events import RaceFinished
from ecs_tentacles.race.game import NOBODY, RaceGame

if TYPE_CHECKING:
    from ecs_tentacles.host import Host


class Referee(ModeReferee[RaceGame]):
    """Runs the clock and ends the race at the flag."""

    name = "race_referee"

    def played(self, world: Host) -> RaceGame:
        return world.resource(RaceGame)

    def judge(self, world: Host, race: RaceGame) -> None:
        state = race.state
        creatures = world.creatures
        there = creatures.entity[race.at_flag(world.transforms.pos[creatures.mantle_row])]
        if race.runner in there:
            state.outcome, state.winner = WON, race.runner
        elif len(there):
            state.outcome, state.winner = LOST, int(np.min(there))
        elif state.frames >= round(race.seconds * race.fps):
            state.outcome, state.winner = LOST, NOBODY
        else:
            return
        world.events.emit(RaceFinished(world, state.outcome, race.elapsed, state.winner))
