"""A scene's `terrain.obstacles` -> `Solid`s (static shapes in every physics model).

Boxes, cylinders and spheres are MuJoCo primitives. A mesh (.obj, .stl, .glb next to
the scene, at most `MAX_MESH_BYTES`) is read with trimesh; a convex one is one piece,
any other is split into convex pieces with CoACD (MuJoCo collides a mesh as its convex
hull, so a concave rock would otherwise fill in its hollows).
"""

from __future__ import annotations

import pathlib
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from ecs_tentacles.ground import Solid, convex_planes
from ecs_tentacles.scene.load import MAX_SCENE_BYTES
from ecs_tentacles.terrain.heights import Problem, TerrainError, beside_scene

MAX_MESH_BYTES = MAX_SCENE_BYTES  # the same cap as a scene file
MESH_SUFFIXES = (".obj", ".stl", ".glb")
MAX_PIECES = 16  # convex pieces per concave mesh (CoACD's max_convex_hull)
# CoACD's search, coarser than its defaults: a 3-box arch splits the same (4 pieces) in
# 2.6 s instead of 14 s; rocks for crawling creatures need no finer hulls
COACD = {
    "max_convex_hull": MAX_PIECES,
    "seed": 0,
    "threshold": 0.1,
    "preprocess_resolution": 30,
    "resolution": 500,
    "mcts_iterations": 60,
    "mcts_max_depth": 2,
}
NEEDS = {
    "box": ("size",),
    "cylinder": ("radius", "height"),
    "sphere": ("radius",),
    "mesh": ("file", "scale"),
}
OPTIONAL = {"scale"}  # a mesh's; the others' keys are all required


def obstacle_problems(obstacles: Sequence[Mapping[str, Any]]) -> list[Problem]:
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
            for key in ("size", "radius", "height", "file", "scale")
            if key in obstacle
            and key not in NEEDS[shape]
            and not (shape == "mesh" and key == "scale")
        )
        if foreign:
            problems.append((here, f"a {shape} takes no {', '.join(map(repr, foreign))}"))
    return problems


def solids(
    obstacles: Sequence[Mapping[str, Any]], folder: pathlib.Path | None
) -> tuple[Solid, ...]:
    """Every obstacle as a `Solid` (schema-valid entries)."""
    for path, message in obstacle_problems(obstacles):
        raise TerrainError(path, message)
    return tuple(_solid(i, o, folder) for i, o in enumerate(obstacles))


def _solid(index: int, obstacle: Mapping[str, Any], folder: pathlib.Path | None) -> Solid:
    shape = obstacle["shape"]
    position = np.asarray(obstacle["position"], dtype=np.float64)
    angles = obstacle.get("rotation_deg", [0.0, 0.0, 0.0])
    rotation = Rotation.from_euler("xyz", angles, degrees=True).as_matrix()
    if shape == "box":
        return Solid("box", position, rotation, tuple(0.5 * float(v) for v in obstacle["size"]))
    if shape == "cylinder":
        size = (float(obstacle["radius"]), 0.5 * float(obstacle["height"]))
        return Solid("cylinder", position, rotation, size)
    if shape == "sphere":
        return Solid("sphere", position, rotation, (float(obstacle["radius"]),))
    here = ("terrain", "obstacles", index, "file")
    pieces = mesh_pieces(obstacle["file"], folder, float(obstacle.get("scale", 1.0)), here)
    planes = tuple(convex_planes(p) for p in pieces)
    return Solid("mesh", position, rotation, pieces=pieces, planes=planes)


def mesh_pieces(
    name: str, folder: pathlib.Path | None, scale: float, here: tuple[str | int, ...]
) -> tuple[np.ndarray, ...]:
    """The convex pieces (vertex arrays, metres) of mesh file `name` scaled by `scale`."""
    import trimesh

    path = beside_scene(name, folder, here)
    if path.suffix.lower() not in MESH_SUFFIXES:
        raise TerrainError(here, f"{name}: a mesh must be one of {', '.join(MESH_SUFFIXES)}")
    if path.stat().st_size > MAX_MESH_BYTES:
        raise TerrainError(here, f"{name}: larger than {MAX_MESH_BYTES >> 20} MB")
    try:
        mesh = trimesh.load(path, force="mesh")
    except Exception as error:  # trimesh raises many kinds for a bad file
        raise TerrainError(here, f"{name}: not a readable mesh ({error})") from None
    vertices = np.asarray(getattr(mesh, "vertices", np.zeros((0, 3))), dtype=np.float64) * scale
    faces = np.asarray(getattr(mesh, "faces", np.zeros((0, 3))), dtype=np.int64)
    if len(faces) == 0 or not np.isfinite(vertices).all():
        raise TerrainError(here, f"{name}: the file holds no triangles with finite vertices")
    if np.ptp(vertices, axis=0).min() <= 1e-9:
        raise TerrainError(here, f"{name}: the mesh is flat (no volume to collide with)")
    if getattr(mesh, "is_convex", False):
        return (vertices,)
    import coacd

    coacd.set_log_level("error")
    parts = coacd.run_coacd(coacd.Mesh(vertices, faces), **COACD)
    return tuple(np.asarray(v, dtype=np.float64) for v, _ in parts)
