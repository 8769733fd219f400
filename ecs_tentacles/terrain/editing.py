"""Editing the terrain of a running world: obstacles placed, moved and deleted, the
heightfield raised, lowered and smoothed with a brush, and the scene saved.

    editor = world.resource(TerrainEditor)
    editor.place(world, "box", (1.0, 2.0, 0.0))        # on the ground at that point
    editor.move(world, 0, (3.0, 0.0, 0.0))
    editor.delete_at(world, (3.0, 0.0, 0.3))            # the obstacle there, if any
    editor.brush(world, "raise", (0.0, 0.0), radius=0.8, amount=0.05)
    editor.save(raw_scene, "edited.json")                # the scene file with the edits

Every edit changes the scene's `terrain` entry (the world's `scene["terrain"]`, which
`save` writes back), makes the `Ground` again and hands it to the world
(`replace_resource`), then recompiles the physics models (`rebuild_models`): no
creature is rebuilt or moved, and a snapshot taken before still restores. A
heightfield given as noise or an image becomes explicit `heights` at its first brush
stroke. An edit that would put an obstacle into a creature is refused
(`TerrainEditError`, one line) and changes nothing.
"""

from __future__ import annotations

import copy
import os
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.ground import Ground, WorldGround, ground_of
from ecs_tentacles.scene.save import save_scene
from ecs_tentacles.terrain.ground import TerrainGround, terrain_ground
from ecs_tentacles.terrain.heights import heightfield
from ecs_tentacles.terrain.scene_ground import build_ground
from ecs_tentacles.terrain.terrain_spec import ObstacleSpec, ShapeKeys, TerrainSpec

if TYPE_CHECKING:
    from ecs_tentacles.host import Host

SHAPES: dict[str, Callable[[float], ShapeKeys]] = {  # a new obstacle: its keys for `size`
    "box": lambda s: {"size": [s, s, 0.5 * s]},
    "cylinder": lambda s: {"radius": 0.5 * s, "height": 0.6 * s},
    "sphere": lambda s: {"radius": 0.5 * s},
    "rock": lambda s: {"size": [s, 0.8 * s, 0.6 * s]},  # a boulder; its seed: its place
}
BRUSHES = ("raise", "lower", "smooth")
PICK_DISTANCE = 0.05  # metres: a point this close to an obstacle picks it
Point = Sequence[float] | np.ndarray  # x, y (and z: `obstacle_at`), in metres


class TerrainEditError(ValueError):
    """An edit that cannot be made (one line; nothing changed)."""


class TerrainEditor:
    """Edits to the terrain of the world it belongs to (see the module doc)."""

    provided_by = "terrain"

    def __init__(self) -> None:
        self.edits = 0  # edits made so far (the sandbox's panel shows it)

    # -- obstacles -----------------------------------------------------------------------
    def place(self, world: Host, shape: str, point: Point, size: float = 0.6) -> int:
        """Put a new `shape` obstacle of `size` m resting on the ground at `point`;
        its index in `terrain.obstacles`."""
        if shape not in SHAPES:
            raise TerrainEditError(f"shape: one of {', '.join(SHAPES)}, got {shape!r}")
        if not 0.05 <= size <= 20.0:
            raise TerrainEditError(f"size: must be in [0.05, 20] m, got {size}")
        x, y = float(point[0]), float(point[1])
        base = float(ground_of(world).surface(np.array([[x, y]]))[0])
        keys = SHAPES[shape](size)
        if shape == "box":
            half = keys["size"][2] / 2
        elif shape == "cylinder":
            half = keys["height"] / 2
        elif shape == "sphere":
            half = 0.6 * keys["radius"]  # sunk a little: a boulder, not a ball on a plane
        else:  # a rock: a third of it in the ground; each a stone of its own
            half = 0.2 * keys["size"][2]
            keys["seed"] = len(self._terrain(world).get("obstacles", []))
        ground = float(ground_of(world).height(np.array([[x, y]]))[0])
        z = base + half - ground  # on_ground: its z is measured from the ground under it
        obstacle: ObstacleSpec = {
            "shape": shape,
            "position": [round(x, 4), round(y, 4), round(z, 4)],
            **keys,
        }
        terrain = self._terrain(world)
        terrain.setdefault("obstacles", []).append(obstacle)
        self._apply(world, terrain)
        return len(terrain["obstacles"]) - 1

    def move(self, world: Host, index: int, point: Point) -> None:
        """Move obstacle `index` so it rests on the ground at `point` (x, y)."""
        terrain = self._terrain(world)
        obstacles = terrain.get("obstacles", [])
        if not 0 <= index < len(obstacles):
            raise TerrainEditError(f"terrain.obstacles[{index}]: there is no such obstacle")
        obstacle = obstacles[index]
        x, y = float(point[0]), float(point[1])
        if obstacle.get("on_ground", True):  # its z is measured from the ground under it
            obstacle["position"] = [round(x, 4), round(y, 4), obstacle["position"][2]]
            self._apply(world, terrain)
            return
        old = ground_of(world).surface(np.array(obstacle["position"][:2], dtype=float))[0]
        lift = obstacle["position"][2] - old
        others = TerrainGround(terrain_ground(world).heightfield)  # without the obstacles
        base = float(others.surface(np.array([[x, y]]))[0])
        obstacle["position"] = [round(x, 4), round(y, 4), round(base + lift, 4)]
        self._apply(world, terrain)

    def obstacle_at(self, world: Host, point: Point) -> int | None:
        """The index of the obstacle at (or within `PICK_DISTANCE` of) `point`, or None."""
        solids = terrain_ground(world).solids
        if not solids:
            return None
        where = np.asarray(point, dtype=np.float64).reshape(1, 3)
        distances = [float(s.signed_distance(where)[0]) for s in solids]
        best = int(np.argmin(distances))
        return best if distances[best] <= PICK_DISTANCE else None

    def delete_at(self, world: Host, point: Point) -> int | None:
        """Remove the obstacle at `point`; its index, or None when nothing is there."""
        index = self.obstacle_at(world, point)
        if index is None:
            return None
        terrain = self._terrain(world)
        del terrain["obstacles"][index]
        self._apply(world, terrain)
        return index

    # -- the heightfield -------------------------------------------------------------------
    def brush(self, world: Host, kind: str, centre: Point, radius: float, amount: float) -> None:
        """Raise, lower (by up to `amount` m at the centre) or smooth (toward the local
        mean, `amount` 0..1 of the way) the heightfield within `radius` m of `centre`."""
        if kind not in BRUSHES:
            raise TerrainEditError(f"brush: one of {', '.join(BRUSHES)}, got {kind!r}")
        terrain = self._terrain(world)
        field = terrain.get("heightfield")
        if not field:
            raise TerrainEditError("terrain.heightfield: this scene has none to sculpt; add one")
        made = heightfield(field, world.scene_dir)
        heights = made.heights.copy()
        rows, cols = heights.shape
        x = np.linspace(-0.5 * made.size[0], 0.5 * made.size[0], cols)
        y = np.linspace(-0.5 * made.size[1], 0.5 * made.size[1], rows)
        gx, gy = np.meshgrid(x, y)
        d2 = (gx - float(centre[0])) ** 2 + (gy - float(centre[1])) ** 2
        weight = np.exp(-d2 / (2.0 * (0.5 * radius) ** 2)) * (d2 <= radius**2)
        if kind == "smooth":
            from scipy.ndimage import uniform_filter

            heights += np.clip(amount, 0.0, 1.0) * weight * (uniform_filter(heights, 3) - heights)
        else:
            heights += (amount if kind == "raise" else -amount) * weight
        field.pop("noise", None)  # its heights now come from no other source
        field.pop("image", None)
        field.pop("resolution", None)
        field.pop("height", None)
        field["heights"] = np.round(heights, 5).tolist()
        self._apply(world, terrain)

    # -- saving ----------------------------------------------------------------------------
    def save(self, world: Host, raw: dict[str, object], path: str | os.PathLike[str]) -> Path:
        """Write scene `raw` (the file as it was read) with the edited terrain to `path`,
        validated and atomically, with the files it names beside it when `path` is in
        another folder than the scene's (`ecs_tentacles.scene.save`)."""
        scene = copy.deepcopy(raw)
        scene["terrain"] = self._terrain(world)
        return save_scene(scene, path, world.plugins, source_dir=world.scene_dir)

    # -- internals -------------------------------------------------------------------------
    def _terrain(self, world: Host) -> TerrainSpec:
        """A copy of the world's current terrain entry (`{}` on the plane)."""
        found: TerrainSpec | None = (world.scene or {}).get("terrain")
        return copy.deepcopy(found) if found else {}

    def _apply(self, world: Host, terrain: TerrainSpec) -> None:
        ground = build_ground(terrain, world.scene_dir)
        _refuse_creatures_inside(world, ground)
        if world.scene is not None:
            world.scene["terrain"] = terrain
        world.replace_resource(WorldGround(ground))
        world.physics.rebuild_models(world)
        self.edits += 1


def _refuse_creatures_inside(world: Host, ground: Ground) -> None:
    """TerrainEditError naming a creature an obstacle of `ground` would be inside."""
    if not ground.has_obstacles:
        return
    from ecs_tentacles.components import Creature

    pos = world.transforms.pos
    for entity, _ in world.query(Creature):
        rows, radii = _bodies(world, entity)
        hit = ground.inside_solid(pos[rows], radii)
        if (hit >= 0).any():
            raise TerrainEditError(
                f"terrain.obstacles[{int(hit[hit >= 0][0])}]: would be inside creature"
                f" {world.creature_name(entity)}"
            )


def _bodies(world: Host, entity: int) -> tuple[np.ndarray, np.ndarray]:
    """Transform rows and radii of a creature's mantle and links."""
    from ecs_tentacles.components import Creature, Link, Tentacle, Transform

    creature = world.component(entity, Creature)
    rows, radii = [world.component(entity, Transform).row], [creature.mantle_radius]
    for tentacle in creature.tentacles:
        for link in world.component(tentacle, Tentacle).links:
            rows.append(world.component(link, Transform).row)
            radii.append(world.component(link, Link).radius)
    return np.array(rows, dtype=np.int64), np.array(radii)
