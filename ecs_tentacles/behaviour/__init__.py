"""What behaviours read and drive, whoever implements it: the dangers creatures fear and
where creatures are sent, through registries (`ecs_tentacles.registry`) that plugins
fill in `build(app)`. Behaviours (fur's emotion, the example plugins, the director's
palette) use these and never name the plugin behind them.

    positions, owners = dangers(world)      # every danger now: (n, 3), (n,) entities
    travel(world).send(world, creature, (x, y), 0.2)   # go there (arrive within 0.2 m)

The phases: `DANGERS_MOVED`, `ARRIVALS`, `DESTINATIONS_READ` (schedule sets the plugins
behind the registries join and behaviours order against), here; the two registries in a
module each, `behaviour.danger_sources` and `behaviour.destinations`, whose names this package
offers too (`from ecs_tentacles.behaviour import travel`).

A `Dangers` entry is a `DangerSource`: `sense(world)` -> the positions (n, 3) of the
dangers it knows now and the creature entity each one is (-1: none; a creature never
fears itself); optionally `drop(world, position, name)` -> the entity of a danger
placed there from now on, `remove(world, entity)` and `placed(world)` -> {entity: name}
of the dangers placed so (the sandbox's palette and its undo). Without any entry
nothing frightens anyone.

A `Destinations` entry is a `Travel`: `send(world, creature, point, radius)` (crawl to
`point`, x, y[, z], arriving within `radius` m, instead of wherever it was going),
`stop(world, creature)` (nowhere to go) and `going(world)` (bool per CreatureStore row:
has somewhere to go). The locomotion plugin adds one (its goals). A system that sends
creatures declares the store columns that writes as its own writes: `writes =
DESTINATION_WRITES` (and reads `DESTINATION_READS` to ask `going`). `DestinationSystem`
is such a system's base: stage `decide`, after `ARRIVALS`, before `DESTINATIONS_READ`,
those writes (the example plugins' systems and the game modes' are).
"""

from __future__ import annotations

from ecs_tentacles.behaviour.danger_sources import Dangers, DangerSource, dangers, placeable
from ecs_tentacles.behaviour.destinations import (
    DESTINATION_READS,
    DESTINATION_WRITES,
    Destinations,
    Travel,
    travel,
)
from ecs_tentacles.system import System

__all__ = [
    "ARRIVALS",
    "DANGERS_MOVED",
    "DESTINATIONS_READ",
    "DESTINATION_READS",
    "DESTINATION_WRITES",
    "DangerSource",
    "Dangers",
    "DestinationSystem",
    "Destinations",
    "Travel",
    "dangers",
    "placeable",
    "travel",
]

# the behaviour phases of a frame, as schedule sets (`System.sets`): what moves dangers,
# what settles who arrived, what reads where creatures go. A behaviour orders against
# these, never against another feature's systems: `after = (ARRIVALS,)`,
# `before = (DESTINATIONS_READ,)` (the example plugins), `after = (DANGERS_MOVED,)` (fur)
DANGERS_MOVED = "dangers_moved"  # the dangers are where they are this frame
ARRIVALS = "arrivals"  # creatures that reached where they went have let it go
DESTINATIONS_READ = "destinations_read"  # where creatures go is read for this frame


class DestinationSystem(System):
    """A system that decides where creatures go, through `travel(world).send` / `stop`:
    in stage `decide`, after the creatures that arrived let their goals go (`ARRIVALS`),
    before where creatures go is read this frame (`DESTINATIONS_READ`), declaring the
    columns that writes (`DESTINATION_WRITES`). A subclass sets `name`, its `reads`
    (with `DESTINATION_READS` to ask `going`) and `process`."""

    stage = "decide"
    after = (ARRIVALS,)
    before = (DESTINATIONS_READ,)
    writes = DESTINATION_WRITES
