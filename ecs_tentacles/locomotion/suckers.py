"""The suckers plugin: tips attach to the ground on command and let go.

Needs locomotion (its actions command attach and detach; its `locomotion` settings
carry the release thresholds). Systems: suckers (stage act). The sucker bodies and
their MuJoCo constraints are core (every creature has them); without this plugin they
stay released unless a script attaches them (`ecs_tentacles.locomotion.grip`:
`attach(world, sucker)`, `release(world, sucker)`, `sucker_points(world)`). Render hook:
each attached sucker as a small yellow sphere at its anchor (an editing aid: not in the
clean view).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.plugin import Plugin
from ecs_tentacles.render.registries import Marker, OverlaySpheres
from ecs_tentacles.system import System

if TYPE_CHECKING:
    from ecs_tentacles.host import Host
    from ecs_tentacles.registry import App

SUCKER_SIZE = (0.024, 0.024, 0.024)  # metres
SUCKER_RGBA = (1.0, 0.92, 0.25, 1.0)


class SuckersPlugin(Plugin):
    name = "suckers"
    build_order = 20  # a default plugin: built after locomotion (10), before threats (30)
    description = "suckers attach at the ground on command; release on command, stretch or reach"
    requires = ("locomotion",)

    def systems(self) -> list[System]:
        from ecs_tentacles.locomotion.systems.suckers import Suckers

        return [Suckers()]

    def build(self, app: App) -> None:
        """Its drawing, HUD sections and clicks (`ecs_tentacles.render.registries`)."""
        app.add(OverlaySpheres, self._spheres)  # an editing aid: none in the clean view

    def _spheres(self, world: Host) -> list[Marker]:
        suckers = world.suckers
        held = np.flatnonzero(suckers.attached)
        if not len(held):
            return []
        return [Marker(suckers.anchor[held] + [0.0, 0.0, 0.01], SUCKER_SIZE, SUCKER_RGBA)]
