"""The ground creatures stand on, as core asks about it: a protocol and the flat default.

Core knows no heightfield and no rock: what shapes the ground (a scene's `terrain`:
heightfields, obstacles, mesh files) is the terrain plugin's, which provides a
`Ground` as a resource (`WorldGround`: an `ecs_tentacles.terrain.ground.TerrainGround`).
Without one the world has `FLAT`: the plane z = 0 and nothing on it.

    ground = ground_of(world)
    ground.height(xy)            # (n,) height of the ground (not obstacles) under (n, 2)
    ground.surface(xy)           # (n,) height of the topmost surface, obstacles too
    ground.normal_under(xy)      # (n, 3) unit normals of the topmost surface there
    ground.distance(points)      # (n,) metres from points (n, 3) to the nearest surface
    ground.inside_solid(balls)   # (n,) the obstacle each ball reaches into, -1: none
    ground.meshes()              # what the renderer draws and takes record

Reads: nothing of the world. Used by the physics model (`add_to_spec`), creature
placement (`ecs_tentacles.scene.construction`), the suckers (they grip any static
surface), the level of detail (obstacles promote), navigation and formations, and the
renderer and take format (`meshes`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Protocol

import mujoco
import numpy as np

__all__ = [
    "FLAT", "Ground", "GroundMesh", "Plane", "StaticContact", "StaticMesh", "StaticSpec",
    "WorldGround", "ground_of",
]  # fmt: skip


class StaticSpec(Protocol):
    """What `Ground.add_to_spec` needs of a `mujoco.MjSpec`."""

    worldbody: mujoco.MjsBody

    def add_hfield(self, **kwargs: object) -> mujoco.MjsHField: ...
    def add_mesh(self, **kwargs: object) -> mujoco.MjsMesh: ...


@dataclass(frozen=True)
class StaticContact:
    """How the static geoms in a creature's model meet its bodies (`physics.model` gives
    it): sliding friction, MuJoCo's contact bits and the contact's `solref`."""

    friction: float
    contype: int
    conaffinity: int
    solref: Sequence[float]

    def geom(self, friction: float | None = None) -> dict[str, object]:
        """`add_geom` keywords for a static geom, its sliding `friction` (when given) in
        place of the model's."""
        return {
            "friction": [self.friction if friction is None else friction, 0.005, 1e-4],
            "contype": self.contype,
            "conaffinity": self.conaffinity,
            "solref": list(self.solref),
        }


@dataclass(frozen=True)
class StaticMesh:
    """Vertices (n, 3), unit normals (n, 3) and triangles (m, 3) of vertex indices."""

    vertices: np.ndarray
    normals: np.ndarray
    triangles: np.ndarray


@dataclass(frozen=True)
class GroundMesh:
    """A named mesh of the ground in world metres: its colour (display rgb, 0..1), how
    strongly the sandbox draws its grid lines on it (0: none), and whether takes record
    it (a picture-only part, the ground beyond a heightfield's edge, is not)."""

    name: str
    mesh: StaticMesh
    rgb: tuple[float, float, float]
    grid: float = 0.0
    recorded: bool = True


class Ground(Protocol):
    """What core and the layers above ask of the ground (`ground_of(world)`)."""

    @property
    def friction(self) -> float | None:
        """Overrides the scene's `physics.ground_friction` when given."""

    @property
    def flat(self) -> bool:
        """The plane z = 0 and nothing on it."""

    @property
    def extent(self) -> np.ndarray | None:
        """(2,) half sizes in x, y of the shaped ground (about the origin); None: the
        plane, without edges."""

    @property
    def has_obstacles(self) -> bool: ...
    def digest(self) -> str:
        """Identifies the geometry (model sharing, takes); "plane" for `FLAT`."""

    def height(self, xy: np.ndarray) -> np.ndarray: ...
    def surface(self, xy: np.ndarray) -> np.ndarray: ...
    def distance(self, points: np.ndarray) -> np.ndarray: ...
    def normal(self, points: np.ndarray) -> np.ndarray: ...
    def normal_under(self, xy: np.ndarray) -> np.ndarray: ...
    def ray(self, origin: np.ndarray, direction: np.ndarray) -> np.ndarray | None: ...
    def lift(self, points: np.ndarray, radii: np.ndarray) -> float:
        """How far to raise balls laid out on z = 0 so they rest on this ground."""

    def inside_solid(
        self, points: np.ndarray, radii: np.ndarray | float = 0.0, only: np.ndarray | None = None
    ) -> np.ndarray: ...
    def solids_near(self, xy: np.ndarray, radius: float) -> np.ndarray:
        """Indices of the obstacles that may come within `radius` m of point `xy`."""

    def touches_obstacle(self, centres: np.ndarray, reach: np.ndarray) -> np.ndarray:
        """(n,) whose sphere (`centres` (n, 3), `reach` (n,)) meets an obstacle."""

    def obstacle_spans(self) -> tuple[np.ndarray, np.ndarray]:
        """(k, 2) the obstacles' centres in x, y and (k,) their largest half extents."""

    def meshes(self) -> list[GroundMesh]: ...
    def add_to_spec(self, spec: StaticSpec, contact: StaticContact) -> None:
        """Add the ground's static geoms (named `ground...`) to a creature's model spec."""


@dataclass(frozen=True)
class Plane:
    """The plane z = 0 with nothing on it: the world's ground without a terrain."""

    friction: float | None = None

    @property
    def flat(self) -> bool:
        return True

    @property
    def extent(self) -> np.ndarray | None:
        return None

    @property
    def has_obstacles(self) -> bool:
        return False

    def digest(self) -> str:
        return "plane" if self.friction is None else f"plane {self.friction!r}"

    def height(self, xy: np.ndarray) -> np.ndarray:
        return np.zeros(len(np.asarray(xy, dtype=np.float64).reshape(-1, 2)))

    def surface(self, xy: np.ndarray) -> np.ndarray:
        return self.height(xy)

    def distance(self, points: np.ndarray) -> np.ndarray:
        return np.asarray(points, dtype=np.float64).reshape(-1, 3)[:, 2].copy()

    def normal(self, points: np.ndarray) -> np.ndarray:
        count = len(np.asarray(points, dtype=np.float64).reshape(-1, 3))
        return np.tile([0.0, 0.0, 1.0], (count, 1))

    def normal_under(self, xy: np.ndarray) -> np.ndarray:
        count = len(np.asarray(xy, dtype=np.float64).reshape(-1, 2))
        return np.tile([0.0, 0.0, 1.0], (count, 1))

    def ray(self, origin: np.ndarray, direction: np.ndarray) -> np.ndarray | None:
        """Where a ray going down meets the plane (None: it never does)."""
        origin = np.asarray(origin, dtype=np.float64).reshape(3)
        direction = np.asarray(direction, dtype=np.float64).reshape(3)
        if direction[2] >= 0.0 or origin[2] <= 0.0:
            return None
        return np.asarray(origin + direction * (-origin[2] / direction[2]))

    def lift(self, points: np.ndarray, radii: np.ndarray) -> float:
        return 0.0

    def inside_solid(
        self, points: np.ndarray, radii: np.ndarray | float = 0.0, only: np.ndarray | None = None
    ) -> np.ndarray:
        return np.full(len(np.asarray(points).reshape(-1, 3)), -1, dtype=np.int64)

    def solids_near(self, xy: np.ndarray, radius: float) -> np.ndarray:
        return np.zeros(0, dtype=np.int64)

    def touches_obstacle(self, centres: np.ndarray, reach: np.ndarray) -> np.ndarray:
        return np.zeros(len(centres), dtype=bool)

    def obstacle_spans(self) -> tuple[np.ndarray, np.ndarray]:
        return np.zeros((0, 2)), np.zeros(0)

    def meshes(self) -> list[GroundMesh]:
        return []  # the renderer draws the plane's grid; takes hold no ground

    def add_to_spec(self, spec: StaticSpec, contact: StaticContact) -> None:
        spec.worldbody.add_geom(
            name="ground",
            type=mujoco.mjtGeom.mjGEOM_PLANE,
            size=[0, 0, 1.0],
            **contact.geom(self.friction),
        )


FLAT = Plane()


@dataclass(frozen=True)
class WorldGround:
    """The world's ground as a resource: the plugin that shapes the ground provides one
    (the terrain plugin; its editor swaps it: `world.replace_resource(WorldGround(new))`)."""

    ground: Ground


def ground_of(world: object) -> Ground:
    """The world's ground (its `WorldGround` resource's), or `FLAT`."""
    getter = getattr(world, "get_resource", None)
    found = getter(WorldGround) if getter is not None else None
    return found.ground if found is not None else FLAT
