"""avoidance: each creature's crowd-avoidance term, from the creatures near it.

Runs after goals, before tentacle_selection, which crawls along the direction to the
steer point turned by this term (`ecs_tentacles.locomotion.avoidance`: a social force
over the pairs of creatures whose personal circles are within the scene's range, found
by the contact proxies' near-pair search). Creatures with a goal and `avoid` on steer;
every creature, with a goal or not, is steered around. The direction a creature is
heading is toward its goal, or toward its navigation waypoint when it follows a route.
Off (`world.resource(Avoidance).enabled` false, the scene's `avoidance.enabled`), every
term is zero.

Reads: Transform store (mantles), CreatureStore (mantle_row, mantle_radius),
TentacleStore (creature_row, length: the personal circles), locomotion's creature store
(has_goal, goal, avoid), the `Navigator`'s waypoints, `Avoidance` (the scene's settings).
Writes: locomotion's creature store (avoidance).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.locomotion.avoidance import Avoidance, bend, personal_radius
from ecs_tentacles.locomotion.navigation import Navigator
from ecs_tentacles.locomotion.stores import LocomotionStores
from ecs_tentacles.physics.pairs import NearPairCache
from ecs_tentacles.system import System

if TYPE_CHECKING:
    from ecs_tentacles.host import Host
    from ecs_tentacles.roster_change import RosterChange


class CrowdAvoidance(System):
    name = "avoidance"
    stage = "decide"
    after = ("goals",)
    before = ("tentacle_selection",)
    reads = (
        "transforms.pos",
        "creatures.mantle_row",
        "creatures.mantle_radius",
        "tentacles.creature_row",
        "tentacles.length",
        "locomotion.creatures.has_goal",
        "locomotion.creatures.goal",
        "locomotion.creatures.avoid",
    )
    writes = ("locomotion.creatures.avoidance",)

    def setup(self, world: Host) -> None:
        self.gaits = world.resource(LocomotionStores).creatures
        self.settings = world.resource(Avoidance)
        self.pairs = NearPairCache()  # neighbours kept between frames while nobody moved far
        self._radii(world)

    def roster_changed(self, world: Host, change: RosterChange) -> None:
        self._radii(world)

    def _radii(self, world: Host) -> None:
        c, t = world.creatures, world.tentacles
        self.radius = personal_radius(c.mantle_radius, t.creature_row, t.length)

    def process(self, world: Host, dt: float) -> None:
        g, settings = self.gaits, self.settings
        steering = g.has_goal & g.avoid
        if not (settings.enabled and steering.any()):
            if g.avoidance.any():
                g.avoidance[:] = 0.0
            return
        mantle = world.transforms.pos[world.creatures.mantle_row, :2]
        to_goal = _heading_point(world, g.goal[:, :2]) - mantle
        distance = np.hypot(to_goal[:, 0], to_goal[:, 1])
        going = (steering & (distance > 0.0))[:, None]
        heading = np.where(going, to_goal / np.maximum(distance, 1e-12)[:, None], 0.0)
        g.avoidance[:] = bend(
            mantle, self.radius, heading, steering, distance, settings.range, settings.strength,
            pairs=self.pairs,
        )  # fmt: skip


def _heading_point(world: Host, goal: np.ndarray) -> np.ndarray:
    """(n, 2) where each creature is heading: its navigation waypoint while it follows a
    route around obstacles (as of the last frame), else its goal."""
    waypoint = world.resource(Navigator).target
    if len(waypoint) != len(goal):
        return goal
    return np.where(np.isnan(waypoint[:, :1]), goal, waypoint[:, :2])
