"""grab: the spring of the director's grab pulls the held body toward the mouse.

Reads: `world.resource(Director).grab` (creature, body, target), the Transform store
(the body's position, last frame's for its speed), the creature's mass (its model).
Writes: the creature's applied force on that body (`xfrc_applied`, stepped with every
substep of the frame) and `grab.force`; when the grab ends, the force is removed. While
held and for a while after, the health check allows the creature a throw's speeds
(`HealthCheck.allow_speed`): a landing's whipping tentacles are not a blow-up. The
director plugin (`ecs_tentacles.director.plugin`) adds it, in the sandbox only.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.components import Creature
from ecs_tentacles.director.grab import spring_force
from ecs_tentacles.director.state import Director
from ecs_tentacles.system import System

THROWN_SPEED = 40.0  # m/s a held or thrown creature's bodies may reach (the scene's: 12)
THROWN_SECONDS = 4.0  # how long after it is let go (a fall and its landing)

if TYPE_CHECKING:
    from ecs_tentacles.host import Host


class GrabSpring(System):
    name = "grab"
    stage = "act"
    reads = ("transforms.pos",)
    writes = ("physics",)

    def __init__(self) -> None:
        self.held: tuple[int, int] | None = None  # (creature, body id) forced last frame

    def process(self, world: Host, dt: float) -> None:
        grab = world.resource(Director).grab
        if grab is None or world.try_component(grab.creature, Creature) is None:
            self.release(world)
            return
        view = world.physics.view_of(world.component(grab.creature, Creature))
        body_id = int(view.body_ids[grab.body])
        if self.held is not None and self.held != (grab.creature, body_id):
            self.release(world)
        position = world.transforms.pos[view.body_rows[grab.body]]
        velocity = np.zeros(3) if grab.last is None else (position - grab.last) / dt
        grab.last = position.copy()
        mass = float(view.model.body_subtreemass[view.body_ids[0]])
        grab.force = spring_force(position, velocity, grab.target, mass)
        applied = view.data.xfrc_applied
        applied[:] = 0.0
        applied[body_id, :3] = grab.force
        self.held = (grab.creature, body_id)
        self._allow_flight(world, grab.creature)

    def _allow_flight(self, world: Host, creature: int) -> None:
        """A creature held or just let go flies and lands faster than a crawl (its
        tentacles whip): the health check allows it `THROWN_SPEED` for `THROWN_SECONDS`."""
        index = world.physics.lod.index(creature)
        world.physics.health.allow_speed(index, THROWN_SPEED, world.time + THROWN_SECONDS)

    def release(self, world: Host) -> None:
        """No force any more on the creature held last frame (if it is still there)."""
        if self.held is None:
            return
        creature, _ = self.held
        self.held = None
        if world.try_component(creature, Creature) is None:
            return
        view = world.physics.view_of(world.component(creature, Creature))
        view.batch.applied.pop(view.row, None)
