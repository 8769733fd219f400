"""steering: the runner goes along the path the player gave it; the rivals go to the flag.

The runner is sent to the first point of its path (`RaceGame.steer`); once it has got
there (the destination let go: `travel(world).going` is False) the point is dropped and
it is sent to the next. From `rivals_wait` seconds on, every rival that has nowhere to
go is sent to the flag, checked every `EVERY` seconds (a send starts a new stroke).
Creatures crawl as their scene says: a level's rivals with `"navigation": false` crawl
straight at the flag (into any wall on the way).

Reads: `RaceGame`, CreatureStore (entity), where creatures go (`DESTINATION_READS`).
Writes: `RaceGame.state` (path, sent, rivals_off); destinations (`DESTINATION_WRITES`,
through `ecs_tentacles.behaviour.travel`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.behaviour import DESTINATION_READS, DestinationSystem, travel
from ecs_tentacles.game.modes import PLAYING
from ecs_tentacles.race.game import RaceGame

if TYPE_CHECKING:
    from ecs_tentacles.host import Host

WAYPOINT_RADIUS = 0.25  # metres: a waypoint of the runner's path is reached within this
EVERY = 0.5  # seconds between looks at the rivals


class Steering(DestinationSystem):
    """The runner along its path, the rivals to the flag."""

    name = "race_steering"
    reads = ("creatures.entity", *DESTINATION_READS)

    def process(self, world: Host, dt: float) -> None:
        race = world.resource(RaceGame)
        state = race.state
        if state.outcome != PLAYING:
            return
        way = travel(world)
        entities = world.creatures.entity
        going = way.going(world)
        runner = np.flatnonzero(entities == race.runner)
        if state.sent is not None and len(runner) and not going[runner[0]]:
            state.path.pop(0)  # got there
            state.sent = None
        if state.path and state.sent is None:
            state.sent = state.path[0]
            radius = race.radius if len(state.path) == 1 else WAYPOINT_RADIUS
            way.send(world, race.runner, state.path[0], radius)
        ready = state.frames >= round(race.rivals_wait * race.fps)
        if not ready or state.frames % max(1, round(EVERY * race.fps)):
            return
        state.rivals_off = True
        idle = np.flatnonzero(~going & (entities != race.runner))
        flag = (float(race.flag[0]), float(race.flag[1]))
        for row in idle.tolist():
            way.send(world, int(entities[row]), flag, 0.5 * race.radius)
