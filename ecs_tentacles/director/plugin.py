"""The director plugin: the sandbox's crowd-directing tools (`ecs_tentacles.director`).

The sandbox turns it on (its entry point is in the `ecs_tentacles.plugins.sandbox`
group); scenes and bakes never see it. Resource: `Director` (the creature held by the
mouse, the scatter brush). System: grab (stage act; `director/systems/grab.py`). Sandbox hooks:
the "Director" HUD section with the palette and the mouse and keys (`director.panel`);
lines for the grab's
spring and the brush. Its `MotionWants` entry: a held creature never sleeps; `despawning`:
removing the held creature ends the grab.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.components import Creature
from ecs_tentacles.director.state import Director
from ecs_tentacles.ground import ground_of
from ecs_tentacles.physics.registries import MotionWants
from ecs_tentacles.plugin import Plugin
from ecs_tentacles.render.registries import Lines, Panels
from ecs_tentacles.render.rings import CIRCLE, draped, line_segments

if TYPE_CHECKING:
    from ecs_tentacles.host import Host
    from ecs_tentacles.registry import App
    from ecs_tentacles.render.registries import Panel, RenderView, SandboxView
    from ecs_tentacles.system import System

GRAB_RGBA = np.array([1.0, 0.85, 0.2, 1.0])
BRUSH_RGBA = np.array([0.6, 0.8, 1.0, 1.0])


class DirectorPlugin(Plugin):
    name = "director"
    description = "the sandbox's crowd tools: palette, scatter, delete, duplicate, grab and throw"

    def resources(self, world: Host) -> list[object]:
        return [Director()]

    def systems(self) -> list[System]:
        from ecs_tentacles.director.systems.grab import GrabSpring

        return [GrabSpring()]

    def build(self, app: App) -> None:
        """Its drawing, HUD sections and clicks (`ecs_tentacles.render.registries`)."""
        app.add(MotionWants, self._wants_motion)
        app.add(Lines, self._lines)
        app.add(Panels, self._panels)

    def _panels(self, sandbox: SandboxView) -> list[Panel]:
        from ecs_tentacles.director.panel import DirectorPanel

        return [DirectorPanel(sandbox)]

    def despawning(self, world: Host, creature: int) -> None:
        """A held creature removed (Delete while dragging, undo, F9): the grab ends."""
        director = world.resource(Director)
        if director.grab is not None and director.grab.creature == creature:
            director.grab = None

    def _wants_motion(self, world: Host) -> np.ndarray | None:
        grab = world.resource(Director).grab
        if grab is None:
            return None
        wanted = np.zeros(len(world.creatures), dtype=bool)
        wanted[world.component(grab.creature, Creature).row] = True
        return wanted

    def _lines(self, world: Host, view: RenderView) -> list[np.ndarray]:
        director = world.resource(Director)
        lines = []
        grab = director.grab
        if grab is not None and world.try_component(grab.creature, Creature) is not None:
            rows = world.physics.view_of(world.component(grab.creature, Creature)).body_rows
            held = view.pos[rows[grab.body]]
            lines.append(line_segments(np.array([held, grab.target]), GRAB_RGBA))
        if director.brush is not None:
            centre, radius = director.brush
            ring = draped(centre + radius * CIRCLE, ground_of(world), 0.02)
            lines.append(line_segments(ring, BRUSH_RGBA))
        return lines
