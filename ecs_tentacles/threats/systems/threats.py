"""threats: path threats follow their keyframed paths (the threats plugin).

Reads: `world.resource(ThreatData).paths` (keyframed positions) and `world.time`. Writes: the
ThreatStore's `pos` of every path threat. Creatures marked `threat` need nothing here:
their mantle is the threat.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ecs_tentacles.behaviour import DANGERS_MOVED
from ecs_tentacles.numeric.keyframes import TrackSet
from ecs_tentacles.system import System
from ecs_tentacles.threats.data import ThreatData

if TYPE_CHECKING:
    from ecs_tentacles.host import Host


class ThreatPaths(System):
    name = "threats"
    stage = "animate"
    sets = (DANGERS_MOVED,)
    reads = ("threats",)  # ThreatData: its paths and store
    writes = ("threats.pos",)

    def __init__(self) -> None:
        self.paths = TrackSet([])
        self.path_count: tuple[int, int] = (-1, -1)

    def process(self, world: Host, dt: float) -> None:
        threats = world.resource(ThreatData)
        seen = (len(threats.paths), threats.version)  # threats dropped or removed at run time
        if seen != self.path_count:
            self.paths = TrackSet(threats.paths)
            self.path_count = seen
        if len(self.paths):
            threats.store.pos[self.paths.rows, self.paths.columns] = self.paths.evaluate(world.time)
