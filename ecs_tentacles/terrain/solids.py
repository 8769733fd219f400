"""A scene's `terrain.obstacles` -> `Solid`s (static shapes in every physics model).

Boxes, cylinders and spheres are MuJoCo primitives. A rock is a noise-displaced
boulder made from its seed (`ecs_tentacles.terrain.rocks`), one convex mesh piece; on a
heightfield it is lowered, if need be, until its lowest point is at or under the lowest
ground beneath it (on a slope no side is in the air). A mesh (.obj, .stl, .glb next to
the scene, at most `MAX_MESH_BYTES`) is read with trimesh; a convex one is one piece,
any other is split into convex pieces with CoACD (MuJoCo collides a mesh as its convex
hull, so a concave rock would otherwise fill in its hollows). Both run in a worker
process with a time and memory budget, once per distinct file
(`ecs_tentacles.terrain.meshes`); a mesh whose coordinates (times its scale) reach past
1000 m, or without a volume (collinear points, one triangle), is refused.
"""

from __future__ import annotations

import dataclasses
import pathlib
from collections.abc import Sequence

import numpy as np

from ecs_tentacles.plugin import Problem
from ecs_tentacles.terrain.heightfield import Heightfield
from ecs_tentacles.terrain.heights import TerrainError
from ecs_tentacles.terrain.meshes import MAX_MESH_BYTES, MESH_SUFFIXES, MeshReader
from ecs_tentacles.terrain.rocks import rock_vertices
from ecs_tentacles.terrain.shapes import Solid, convex_planes
from ecs_tentacles.terrain.terrain_spec import ObstacleSpec

__all__ = ["MAX_MESH_BYTES", "MESH_SUFFIXES", "obstacle_problems", "solids"]

NEEDS = {
    "box": ("size",),
    "cylinder": ("radius", "height"),
    "sphere": ("radius",),
    "mesh": ("file", "scale"),
    "rock": ("size", "seed"),
}
OPTIONAL = {"scale", "seed"}  # a mesh's scale (1), a rock's seed (0); the others' are required


def obstacle_problems(obstacles: Sequence[ObstacleSpec]) -> list[Problem]:
    """What the schema cannot say: each shape has the keys it needs and no others'."""
    problems: list[Problem] = []
    for i, obstacle in enumerate(obstacles):
        shape = obstacle["shape"]
        here = ("terrain", "obstacles", i)
        for key in NEEDS[shape]:
            if key not in obstacle and key not in OPTIONAL:
                problems.append((here, f"a {shape} needs {key!r}"))
        foreign = sorted(
            key
            for key in ("size", "radius", "height", "file", "scale", "seed")
            if key in obstacle and key not in NEEDS[shape]
        )
        if foreign:
            problems.append((here, f"a {shape} takes no {', '.join(map(repr, foreign))}"))
    return problems


def solids(
    obstacles: Sequence[ObstacleSpec],
    folder: pathlib.Path | None,
    field: Heightfield | None = None,
) -> tuple[Solid, ...]:
    """Every obstacle as a `Solid` (schema-valid entries); on `field`, those `on_ground`
    (the default) raised by the ground's height under their centre."""
    for path, message in obstacle_problems(obstacles):
        raise TerrainError(path, message)
    planes: dict[int, tuple[np.ndarray, ...]] = {}  # id(pieces) -> their planes, made once
    with MeshReader(folder) as reader:
        made = [_solid(i, o, reader, planes) for i, o in enumerate(obstacles)]
    if field is None:
        return tuple(made)
    standing = [i for i, o in enumerate(obstacles) if o.get("on_ground", True)]
    if standing:
        centres = np.array([made[i].position[:2] for i in standing])
        for i, lift in zip(standing, field.height(centres).tolist(), strict=True):
            if obstacles[i]["shape"] == "rock":  # no lower side in the air: sunk as needed
                outline = made[i].pieces[0] @ made[i].rotation.T + made[i].position
                lowest = float(field.height(outline[:, :2]).min())
                lift = min(lift, lowest - float(outline[:, 2].min()))
            made[i] = dataclasses.replace(made[i], position=made[i].position + [0.0, 0.0, lift])
    return tuple(made)


def _solid(
    index: int,
    obstacle: ObstacleSpec,
    reader: MeshReader,
    known: dict[int, tuple[np.ndarray, ...]],
) -> Solid:
    shape = obstacle["shape"]
    position = np.asarray(obstacle["position"], dtype=np.float64)
    angles = obstacle.get("rotation_deg", [0.0, 0.0, 0.0])
    from scipy.spatial.transform import Rotation  # here: a slow import

    rotation = Rotation.from_euler("xyz", angles, degrees=True).as_matrix()
    if shape == "box":
        return Solid("box", position, rotation, tuple(0.5 * float(v) for v in obstacle["size"]))
    if shape == "cylinder":
        size = (float(obstacle["radius"]), 0.5 * float(obstacle["height"]))
        return Solid("cylinder", position, rotation, size)
    if shape == "sphere":
        return Solid("sphere", position, rotation, (float(obstacle["radius"]),))
    if shape == "rock":
        vertices = rock_vertices(obstacle["size"], int(obstacle.get("seed", 0)))
        return Solid(
            "mesh", position, rotation, pieces=(vertices,), planes=(convex_planes(vertices),)
        )
    here = ("terrain", "obstacles", index, "file")
    pieces = reader.pieces(obstacle["file"], float(obstacle.get("scale", 1.0)), here)
    planes = known.get(id(pieces))
    if planes is None:
        try:
            planes = known[id(pieces)] = tuple(convex_planes(p) for p in pieces)
        except (RuntimeError, ValueError):  # scipy's QhullError: a piece too thin for faces
            message = f"{obstacle['file']}: a convex piece of it has no volume"
            raise TerrainError(here, message) from None
    return Solid("mesh", position, rotation, pieces=pieces, planes=planes)
