"""The ground in a take: the terrain and obstacles as static meshes, for the exporters.

A take recorded on the plane has no `header["ground"]` (or null): nothing changes for
it. On terrain, `header["ground"]` is

    {"digest": "<Ground.digest()>",
     "meshes": [{"name": "terrain", "vertices": n, "triangles": m}, ...]}

with, per mesh (in that order, after the tracks' arrays), three arrays:

    ground_<name>_points     float32 (n, 3)   world metres
    ground_<name>_normals    float32 (n, 3)   unit normals
    ground_<name>_triangles  uint32  (m, 3)   vertex indices, counter-clockwise from outside

Mesh names are `MESH_NAMES` (`ecs_tentacles.ground.meshes`: the heightfield's surface and
every obstacle in one mesh). Readers check the entry and that every triangle index is
below its mesh's vertex count before an exporter sees them.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ecs_tentacles.ground import Ground
from ecs_tentacles.ground.meshes import StaticMesh, ground_meshes

KEY = "ground"
MESH_NAMES = ("terrain", "obstacles")
MAX_VERTICES = 1025 * 1025 * 4  # the largest heightfield's grid, with room for obstacles
PARTS = (("points", "<f4", 3), ("normals", "<f4", 3), ("triangles", "<u4", 3))


def array_name(mesh: str, part: str) -> str:
    return f"ground_{mesh}_{part}"


def header_entry_and_arrays(ground: Ground) -> tuple[dict[str, Any] | None, dict[str, np.ndarray]]:
    """`header["ground"]` and the arrays for `ground` (None and none on the plane)."""
    meshes = dict(zip(MESH_NAMES, ground_meshes(ground), strict=True))
    present = {name: mesh for name, mesh in meshes.items() if mesh is not None}
    if not present:
        return None, {}
    arrays: dict[str, np.ndarray] = {}
    entries = []
    for name, mesh in present.items():
        entries.append(
            {"name": name, "vertices": len(mesh.vertices), "triangles": len(mesh.triangles)}
        )
        arrays[array_name(name, "points")] = mesh.vertices.astype("<f4")
        arrays[array_name(name, "normals")] = mesh.normals.astype("<f4")
        arrays[array_name(name, "triangles")] = mesh.triangles.astype("<u4")
    return {"digest": ground.digest(), "meshes": entries}, arrays


def entries(header: dict[str, Any]) -> list[dict[str, Any]]:
    """The meshes `header` declares (none on the plane); the header must be sound."""
    ground = header.get(KEY)
    return [] if ground is None else list(ground["meshes"])


def problem(header: dict[str, Any]) -> str | None:
    """The first problem of `header["ground"]`, or None."""
    ground = header.get(KEY)
    if ground is None:
        return None
    if not isinstance(ground, dict) or set(ground) != {"digest", "meshes"}:
        return f"header.{KEY}: must be null or an object with digest and meshes"
    if not isinstance(ground["digest"], str):
        return f"header.{KEY}.digest: must be a string"
    meshes = ground["meshes"]
    if not isinstance(meshes, list) or not 1 <= len(meshes) <= len(MESH_NAMES):
        return f"header.{KEY}.meshes: must list 1 to {len(MESH_NAMES)} meshes"
    seen = set()
    for i, mesh in enumerate(meshes):
        where = f"header.{KEY}.meshes[{i}]"
        if not isinstance(mesh, dict) or set(mesh) != {"name", "vertices", "triangles"}:
            return f"{where}: must be an object with name, vertices and triangles"
        if mesh["name"] not in MESH_NAMES or mesh["name"] in seen:
            return f"{where}.name: must be one of {', '.join(MESH_NAMES)}, each once"
        seen.add(mesh["name"])
        for key in ("vertices", "triangles"):
            value = mesh[key]
            if (
                isinstance(value, bool)
                or not isinstance(value, int)
                or not 1 <= value <= MAX_VERTICES * 2
            ):
                return f"{where}.{key}: must be a whole number in [1, {MAX_VERTICES * 2}]"
    return None


def shapes(header: dict[str, Any]) -> dict[str, tuple[int, ...]]:
    """Array name -> shape for a sound header."""
    out: dict[str, tuple[int, ...]] = {}
    for mesh in entries(header):
        for part, _, width in PARTS:
            rows = mesh["triangles"] if part == "triangles" else mesh["vertices"]
            out[array_name(mesh["name"], part)] = (rows, width)
    return out


def dtypes(header: dict[str, Any]) -> dict[str, np.dtype[Any]]:
    """Array name -> dtype, in file order, for a sound header."""
    return {
        array_name(mesh["name"], part): np.dtype(dtype)
        for mesh in entries(header)
        for part, dtype, _ in PARTS
    }


def index_problem(header: dict[str, Any], arrays: dict[str, np.ndarray]) -> str | None:
    """A triangle index at or past its mesh's vertex count, or None."""
    for mesh in entries(header):
        name = array_name(mesh["name"], "triangles")
        triangles = arrays.get(name)
        if triangles is not None and len(triangles) and int(triangles.max()) >= mesh["vertices"]:
            return f"{name}: index {int(triangles.max())} past the {mesh['vertices']} vertices"
    return None


def meshes_of(
    header: dict[str, Any], arrays: dict[str, np.ndarray]
) -> list[tuple[str, StaticMesh]]:
    """(name, mesh) of every ground mesh a (sound) take holds, for the exporters."""
    return [
        (
            mesh["name"],
            StaticMesh(
                arrays[array_name(mesh["name"], "points")],
                arrays[array_name(mesh["name"], "normals")],
                arrays[array_name(mesh["name"], "triangles")],
            ),
        )
        for mesh in entries(header)
    ]
