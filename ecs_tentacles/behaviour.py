"""What behaviours read and drive, whoever implements it: the dangers creatures fear and
where creatures are sent, through registries (`ecs_tentacles.registry`) that plugins
fill in `build(app)`. Behaviours (fur's emotion, the example plugins, the director's
palette) use these and never name the plugin behind them.

    positions, owners = dangers(world)      # every danger now: (n, 3), (n,) entities
    travel(world).send(world, creature, (x, y), 0.2)   # go there (arrive within 0.2 m)

The phases: `DANGERS_MOVED`, `ARRIVALS`, `DESTINATIONS_READ` (schedule sets the plugins
behind the registries join and behaviours order against).

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
DESTINATION_WRITES` (and reads `DESTINATION_READS` to ask `going`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.registry import Registry

if TYPE_CHECKING:
    from ecs_tentacles.host import Host

# the behaviour phases of a frame, as schedule sets (`System.sets`): what moves dangers,
# what settles who arrived, what reads where creatures go. A behaviour orders against
# these, never against another feature's systems: `after = (ARRIVALS,)`,
# `before = (DESTINATIONS_READ,)` (the example plugins), `after = (DANGERS_MOVED,)` (fur)
DANGERS_MOVED = "dangers_moved"  # the dangers are where they are this frame
ARRIVALS = "arrivals"  # creatures that reached where they went have let it go
DESTINATIONS_READ = "destinations_read"  # where creatures go is read for this frame

# the store columns the `Destinations` entry (the locomotion plugin's goals) writes when a
# system sends or stops a creature, and reads for `going`: such a system declares them
DESTINATION_WRITES = (
    "goals",
    "locomotion.creatures.goal",
    "locomotion.creatures.has_goal",
    "locomotion.creatures.goal_radius",
)
DESTINATION_READS = ("locomotion.creatures.has_goal",)


@dataclass(frozen=True)
class DangerSource:
    """Dangers one plugin knows, and (optionally) how to place and take them away."""

    sense: Callable[[Host], tuple[np.ndarray, np.ndarray]]
    drop: Callable[[Host, Sequence[float], str], int] | None = None
    remove: Callable[[Host, int], None] | None = None
    placed: Callable[[Host], dict[int, str]] | None = None


class Dangers(Registry[DangerSource]):
    """The world's sources of danger."""


def dangers(world: Host) -> tuple[np.ndarray, np.ndarray]:
    """Every danger now: positions (n, 3) and owner creature entities (n,; -1: none)."""
    found = [source.sense(world) for source in world.registry(Dangers)]
    if not found:
        return np.zeros((0, 3)), np.zeros(0, dtype=np.int64)
    positions = np.concatenate([np.asarray(p, dtype=np.float64).reshape(-1, 3) for p, _ in found])
    owners = np.concatenate([np.asarray(o, dtype=np.int64).reshape(-1) for _, o in found])
    return positions, owners


def placeable(world: Host) -> DangerSource | None:
    """The first source that can place dangers (`drop`), or None."""
    return next((s for s in world.registry(Dangers) if s.drop is not None), None)


@dataclass(frozen=True)
class Travel:
    """How a plugin sends creatures toward points (the locomotion plugin: goals)."""

    send: Callable[[Host, int, Sequence[float], float], object]  # what it returns is unused
    stop: Callable[[Host, int], None]
    going: Callable[[Host], np.ndarray]


class Destinations(Registry[Travel]):
    """Who moves creatures toward points."""


def travel(world: Host) -> Travel:
    """The world's first `Travel` (`Destinations` entry); LookupError without one."""
    found = next(iter(world.registry(Destinations)), None)
    if found is None:
        raise LookupError(
            "no plugin sends creatures anywhere (none of those on adds a Destinations entry)"
        )
    return found
