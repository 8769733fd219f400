"""The threats plugin: scene `threats` (keyframed paths) and creatures marked `threat`.

Scene keys: `threats` and a creature's `threat` (`assets/schema/plugins/threats.json`).
Resources: `world.threats` (`ecs_tentacles.threats.ThreatData`). Systems: threats
(stage animate). The fur plugin's emotion reads them; render hook: dark red markers.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

import numpy as np

from ecs_tentacles.plugin import Marker, Plugin
from ecs_tentacles.scene.validate import fragment
from ecs_tentacles.system import System
from ecs_tentacles.threats import ThreatData, build_threats, mark_creature, threat_problems

if TYPE_CHECKING:
    from ecs_tentacles.world import World

_FRAGMENT = fragment("threats")
THREAT_SIZE = (0.07, 0.045, 0.04)  # metres along x, y, z
THREAT_RGBA = (0.35, 0.12, 0.08, 1.0)


class ThreatsPlugin(Plugin):
    name = "threats"
    description = "marked threats on keyframed paths, and creatures marked as threats"
    creature_schema = _FRAGMENT["creature"]
    scene_schema = _FRAGMENT["scene"]
    defs = _FRAGMENT["$defs"]

    def problems(self, scene: Mapping[str, Any]) -> list[tuple[tuple[str | int, ...], str]]:
        return threat_problems(scene)

    def resources(self, world: World) -> dict[str, Any]:
        return {"threats": ThreatData()}

    def build_creature(self, world: World, creature: int, spec: Mapping[str, Any]) -> None:
        if spec.get("threat"):
            mark_creature(world, creature)

    def build_scene(self, world: World, scene: Mapping[str, Any]) -> None:
        build_threats(world, scene["threats"])

    def systems(self) -> list[System]:
        from ecs_tentacles.systems.threats import ThreatPaths

        return [ThreatPaths()]

    def snapshot(self, world: World) -> Any:
        return world.threats.store.copy_rows()

    def restore(self, world: World, state: Any) -> None:
        world.threats.store.put_rows(state)

    def render_spheres(self, world: World) -> list[Marker]:
        positions = list(world.threats.positions(world).values())
        if not positions:
            return []
        return [Marker(np.array(positions) + [0.0, 0.0, 0.04], THREAT_SIZE, THREAT_RGBA)]
