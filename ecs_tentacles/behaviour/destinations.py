"""Where creatures are sent: the `Destinations` registry (entries: `Travel`) that a plugin
fills in `build(app)` (the locomotion plugin: its goals), `travel(world)` that behaviours
send creatures through, and the store columns such a system declares
(`DESTINATION_WRITES`, `DESTINATION_READS`). Reads the world's `Destinations` entries;
writes nothing itself.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.registry import Registry

if TYPE_CHECKING:
    from ecs_tentacles.host import Host

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
