"""The terrain plugin: scene key `terrain` -> the world's `Ground` (heightfield, obstacles).

Scene key: `terrain` (`ecs_tentacles/terrain/terrain.schema.json`). Resource: the core
`ecs_tentacles.ground.Ground` (`ground_of(world)`), which every physics model, the
creatures' placement and the suckers read; without a `terrain` key it is the plane z = 0
and nothing changes. Checks: one heightfield source, each obstacle's keys, files next
to the scene; at build, no creature or goal inside an obstacle (with
`physics.separate_overlaps` a creature is moved out instead, and says so).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

import numpy as np

from ecs_tentacles.construction import creature_layout
from ecs_tentacles.ground import FLAT, Ground, ground_of
from ecs_tentacles.plugin import Plugin
from ecs_tentacles.scene.errors import SceneError
from ecs_tentacles.scene.schema import fragment
from ecs_tentacles.scene.validate import format_path
from ecs_tentacles.terrain.heights import TerrainError, heightfield, source_problems
from ecs_tentacles.terrain.solids import obstacle_problems, solids

if TYPE_CHECKING:
    from ecs_tentacles.host import Host

_FRAGMENT = fragment("ecs_tentacles.terrain", "terrain")


class TerrainPlugin(Plugin):
    name = "terrain"
    description = "a heightfield and static obstacles instead of the flat plane"
    scene_schema = _FRAGMENT["scene"]
    defs = _FRAGMENT["$defs"]

    def problems(self, scene: Mapping[str, Any]) -> list[tuple[tuple[str | int, ...], str]]:
        terrain = scene.get("terrain") or {}
        found = []
        if "heightfield" in terrain:
            found += source_problems(terrain["heightfield"])
        return found + obstacle_problems(terrain.get("obstacles", []))

    def resources(self, world: Host) -> list[object]:
        return [build_ground((world.scene or {}).get("terrain") or {}, world.scene_dir)]

    def build_scene(self, world: Host, scene: Mapping[str, Any]) -> None:
        ground = ground_of(world)
        if not ground.solids:
            return
        problems = []
        for i, creature in enumerate(scene["creatures"]):
            starts, ends, radii = creature_layout(creature, ground).capsules()
            points = np.concatenate([starts, ends, 0.5 * (starts + ends)])
            hit = ground.inside_solid(points, np.concatenate([radii, radii, radii]))
            if (hit >= 0).any():
                problems.append(
                    f"creatures[{i}].position: {creature['name']} is inside"
                    f" terrain.obstacles[{int(hit[hit >= 0][0])}]; move it or the obstacle"
                )
        if problems:
            raise SceneError(problems)


def build_ground(terrain: Mapping[str, Any], folder: Any) -> Ground:
    """The `Ground` a scene's `terrain` describes (FLAT for `{}`); SceneError names the
    field when a file is missing or bad."""
    if (
        not terrain.get("heightfield")
        and not terrain.get("obstacles")
        and "friction" not in terrain
    ):
        return FLAT
    try:
        field = heightfield(terrain["heightfield"], folder) if terrain.get("heightfield") else None
        shapes = solids(terrain.get("obstacles", []), folder)
    except TerrainError as error:
        raise SceneError([f"{format_path(error.path)}: {error}"]) from None
    friction = terrain.get("friction")
    return Ground(field, shapes, None if friction is None else float(friction))
