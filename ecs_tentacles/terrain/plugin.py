"""The terrain plugin: scene key `terrain` -> the world's `Ground` (heightfield, obstacles).

Scene key: `terrain` (`ecs_tentacles/terrain/terrain.schema.json`). Resources: the
world's ground (`WorldGround` of a `TerrainGround`: `ground_of(world)`), which every
physics model (its `StaticGeometry` entry), the creatures' placement, the suckers, the
renderer and takes read (without a `terrain` key it is the plane z = 0 and nothing
changes), and the `TerrainEditor` (`ecs_tentacles.terrain.editing`).
Sandbox: the "Terrain" HUD section (`ecs_tentacles.terrain.panel`).
Checks: one heightfield source, each obstacle's keys, files next to the scene; at
build, no creature inside an obstacle, none given a 3-d position inside the
heightfield, and no 3-d goal inside an obstacle (a 2-d goal rests on the topmost
surface: on top of an obstacle, never inside).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.ground import WorldGround, ground_of
from ecs_tentacles.physics.model import StaticGeometry
from ecs_tentacles.plugin import Plugin, Problem
from ecs_tentacles.render.registries import Panels
from ecs_tentacles.scene.errors import SceneError
from ecs_tentacles.scene.schema import plugin_schemas
from ecs_tentacles.scene.spec import as_spec
from ecs_tentacles.terrain.editing import TerrainEditor
from ecs_tentacles.terrain.heights import source_problems
from ecs_tentacles.terrain.scene_ground import build_ground
from ecs_tentacles.terrain.solids import obstacle_problems
from ecs_tentacles.terrain.terrain_spec import TerrainSpec

if TYPE_CHECKING:
    from ecs_tentacles.host import Host
    from ecs_tentacles.registry import App
    from ecs_tentacles.render.registries import Panel, SandboxView

SINK_TOLERANCE = 0.001  # metres a 3-d placed creature may start inside the heightfield


class TerrainPlugin(Plugin):
    name = "terrain"
    build_order = 60  # a default plugin: built after clips (50)
    description = "a heightfield and static obstacles instead of the flat plane"
    creature_schema, tentacle_schema, scene_schema, defs = plugin_schemas(__package__, name)

    def problems(self, scene: Mapping[str, object]) -> list[Problem]:
        terrain = scene.get("terrain")
        if not isinstance(terrain, dict):  # (an object, if given: the schema says so)
            return []
        found = []
        if "heightfield" in terrain:
            found += source_problems(terrain["heightfield"])
        return found + obstacle_problems(terrain.get("obstacles", []))

    def scene_files(self, scene: Mapping[str, object]) -> list[tuple[tuple[str | int, ...], str]]:
        terrain = scene.get("terrain")
        if not isinstance(terrain, dict):
            return []
        files: list[tuple[tuple[str | int, ...], str]] = []
        field = terrain.get("heightfield") or {}
        if isinstance(field.get("image"), str):
            files.append((("terrain", "heightfield", "image"), field["image"]))
        for i, obstacle in enumerate(terrain.get("obstacles") or []):
            if isinstance(obstacle.get("file"), str):
                files.append((("terrain", "obstacles", i, "file"), obstacle["file"]))
        return files

    def resources(self, world: Host) -> list[object]:
        terrain: TerrainSpec | None = (world.scene or {}).get("terrain")
        ground = build_ground(terrain or {}, world.scene_dir)
        return [WorldGround(ground), TerrainEditor()]

    def shapes_ground(self, scene: Mapping[str, object]) -> bool:
        """A heightfield: its own check (`build_scene`) puts creatures above it."""
        terrain = scene.get("terrain")
        return isinstance(terrain, dict) and bool(terrain.get("heightfield"))

    def build(self, app: App) -> None:
        """Its heightfield and solids in every creature's model (`physics.registries`:
        the world's ground as it is when a model is built, edits included) and its HUD
        section (`render.registries`)."""
        world = app.world
        if world is not None:  # (a shard planner builds plugins without a world)
            app.add(
                StaticGeometry, lambda spec, contact: ground_of(world).add_to_spec(spec, contact)
            )
        app.add(Panels, self._panels)

    def _panels(self, sandbox: SandboxView) -> list[Panel]:
        from ecs_tentacles.terrain.panel import TerrainPanel

        return [TerrainPanel(sandbox)]

    def build_scene(self, world: Host, scene: Mapping[str, object]) -> None:
        ground = ground_of(world)
        creatures = scene.get("creatures")
        if ground.flat or not isinstance(creatures, list):  # (a list: the schema says so)
            return
        problems = []
        for i, creature in enumerate(creatures):
            starts, ends, radii = world.layouts.on(as_spec(creature), ground).capsules()
            points = np.concatenate([starts, ends, 0.5 * (starts + ends)])
            balls = np.concatenate([radii, radii, radii])
            where = f"creatures[{i}].position: {creature['name']}"
            reach = float(np.max(np.linalg.norm(points[:, :2] - starts[0, :2], axis=1)))
            near = ground.solids_near(starts[0, :2], reach + float(balls.max()))
            hit = ground.inside_solid(points, balls, near)
            if (hit >= 0).any():
                problems.append(
                    f"{where} is inside terrain.obstacles[{int(hit[hit >= 0][0])}];"
                    " move it or the obstacle"
                )
            for j, goal in enumerate(creature.get("goals", [])):
                if len(goal["position"]) == 3:  # a 2-d goal rests on the topmost surface
                    inside = ground.inside_solid(np.asarray(goal["position"], dtype=float))
                    if inside[0] >= 0:
                        problems.append(
                            f"creatures[{i}].goals[{j}].position: inside"
                            f" terrain.obstacles[{int(inside[0])}]; give [x, y] to put it"
                            " on top, or move it"
                        )
            if len(creature["position"]) == 3 and ground.extent is not None:
                # a 2-d position is placed on the surface; a 3-d one must be above it (the
                # links' balls, and the mantle's flat base: not its capsule's round end)
                links = np.concatenate([starts[1:], ends[1:], 0.5 * (starts + ends)[1:]])
                low = np.concatenate([links[:, 2] - np.tile(radii[1:], 3), [starts[0, 2]]])
                xy = np.concatenate([links[:, :2], starts[:1, :2]])
                sunk = float(np.max(ground.height(xy) - low))
                if sunk > SINK_TOLERANCE:
                    problems.append(
                        f"{where} starts {1e3 * sunk:.0f} mm inside the terrain; raise its z"
                        " or give [x, y] to rest it on the surface"
                    )
        if problems:
            raise SceneError(problems)
