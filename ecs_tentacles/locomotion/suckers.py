"""The suckers plugin: tips attach to the ground on command and let go.

Needs locomotion (its actions command attach and detach; its `locomotion` settings
carry the release thresholds). Systems: suckers (stage act). The sucker bodies and
their MuJoCo constraints are core (every creature has them); without this plugin they
stay released unless a script attaches them (`ecs_tentacles.locomotion.grip`:
`attach(world, sucker)`, `release(world, sucker)`, `sucker_points(world)`).
"""

from __future__ import annotations

from ecs_tentacles.plugin import Plugin
from ecs_tentacles.system import System


class SuckersPlugin(Plugin):
    name = "suckers"
    description = "suckers attach at the ground on command; release on command, stretch or reach"
    requires = ("locomotion",)

    def systems(self) -> list[System]:
        from ecs_tentacles.systems.locomotion.suckers import Suckers

        return [Suckers()]
