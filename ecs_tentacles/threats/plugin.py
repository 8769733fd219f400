"""The threats plugin: scene `threats` (keyframed paths) and creatures marked `threat`.

Scene keys: `threats` and a creature's `threat` (`ecs_tentacles/threats/threats.schema.json`).
Resources: `world.resource(ThreatData)` (`ecs_tentacles.threats.ThreatData`). Systems: threats
(stage animate). The fur plugin's emotion reads them; its `Spheres` entry: dark red markers.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.behaviour import Dangers, DangerSource
from ecs_tentacles.plugin import Plugin, Problem
from ecs_tentacles.render.registries import Marker, Spheres
from ecs_tentacles.scene.schema import plugin_schemas
from ecs_tentacles.system import System
from ecs_tentacles.threats.data import (
    ThreatData,
    build_threats,
    mark_creature,
    scene_threats,
    threat_problems,
)

if TYPE_CHECKING:
    from ecs_tentacles.host import Host
    from ecs_tentacles.registry import App
    from ecs_tentacles.roster_change import RosterChange
    from ecs_tentacles.store import ArrayStore

THREAT_SIZE = (0.07, 0.045, 0.04)  # metres along x, y, z
THREAT_RGBA = (0.35, 0.12, 0.08, 1.0)


class ThreatsPlugin(Plugin):
    name = "threats"
    build_order = 30  # a default plugin: built after suckers (20), before fur (40)
    description = "marked threats on keyframed paths, and creatures marked as threats"
    creature_schema, tentacle_schema, scene_schema, defs = plugin_schemas(__package__, name)
    hook_reads = ("threats", "transforms.pos")  # its Dangers entry (`behaviour.dangers`)

    def problems(self, scene: Mapping[str, object]) -> list[Problem]:
        return threat_problems(scene)

    def resources(self, world: Host) -> list[object]:
        return [ThreatData()]

    def build_creature(self, world: Host, creature: int, spec: Mapping[str, object]) -> None:
        if spec.get("threat"):
            mark_creature(world, creature)

    def roster_changed(self, world: Host, change: RosterChange) -> None:
        if change.spawned:
            return  # `build_creature` marked it, if it is a threat
        threats = world.resource(ThreatData)
        keep = threats.creatures != change.creature
        threats.creatures = threats.creatures[keep]
        threats.bodies = change.moved["transforms"][threats.bodies[keep]]

    def save_scene(self, world: Host, scene: dict[str, object]) -> None:
        """The scene's threats still there, and the ones dropped since (where they stand)."""
        here = world.resource(ThreatData).positions(world)
        kept = [t for t in scene_threats(scene) if t.get("name") in here]
        named = {t.get("name") for t in kept}
        dropped = [
            {"name": name, "path": [{"time": 0.0, "position": [round(float(v), 6) for v in pos]}]}
            for name, pos in here.items()
            if name not in named
        ]
        if kept or dropped:
            scene["threats"] = kept + dropped

    def build_scene(self, world: Host, scene: Mapping[str, object]) -> None:
        build_threats(world, scene_threats(scene))

    def systems(self) -> list[System]:
        from ecs_tentacles.threats.systems.threats import ThreatPaths

        return [ThreatPaths()]

    def stores(self, world: Host) -> dict[str, ArrayStore]:
        return {"threats": world.resource(ThreatData).store}  # copied by snapshots

    def build(self, app: App) -> None:
        """Its dangers (`ecs_tentacles.behaviour`) and its spheres (`render.registries`)."""
        app.add(
            Dangers,
            DangerSource(
                sense=lambda world: world.resource(ThreatData).sources(world),
                drop=lambda world, at, name: world.resource(ThreatData).drop(world, at, name),
                remove=lambda world, threat: world.resource(ThreatData).remove(world, threat),
                placed=lambda world: world.resource(ThreatData).entities(world),
            ),
        )
        app.add(Spheres, self._spheres)

    def _spheres(self, world: Host) -> list[Marker]:
        positions = list(world.resource(ThreatData).positions(world).values())
        if not positions:
            return []
        return [Marker(np.array(positions) + [0.0, 0.0, 0.04], THREAT_SIZE, THREAT_RGBA)]
