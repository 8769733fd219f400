"""The ground in a take: the terrain and obstacles as static meshes, for the exporters.

A take recorded on the plane has no `header["ground"]` (or null): nothing changes for
it. On terrain, `header["ground"]` is

    {"digest": "<Ground.digest()>",
     "meshes": [{"name": "terrain", "vertices": n, "triangles": m, "rgb": [r, g, b]}, ...]}

with, per mesh (in that order, after the tracks' arrays), three arrays:

    ground_<name>_points     float32 (n, 3)   world metres
    ground_<name>_normals    float32 (n, 3)   unit normals
    ground_<name>_triangles  uint32  (m, 3)   vertex indices, counter-clockwise from outside

The meshes are those the world's ground records (`Ground.meshes`, each with its name
and colour: the terrain plugin's heightfield surface and its obstacles in one mesh); a
name is an identifier, each once, at most `MAX_MESHES`; `rgb` (display colour, 0..1)
is absent in takes written before meshes carried it. Readers check the entry and that
every triangle index is below its mesh's vertex count before an exporter sees them.
"""

from __future__ import annotations

import math
import re
from typing import Any

import numpy as np

from ecs_tentacles.ground import Ground, StaticMesh
from ecs_tentacles.take.header_entries import GroundMeshEntry, HeaderGround

KEY = "ground"
MAX_MESHES = 8
_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]{0,39}$")
MAX_VERTICES = 1025 * 1025 * 4  # the largest heightfield's grid, with room for obstacles
PARTS = (("points", "<f4", 3), ("normals", "<f4", 3), ("triangles", "<u4", 3))


def array_name(mesh: str, part: str) -> str:
    return f"ground_{mesh}_{part}"


def header_entry_and_arrays(ground: Ground) -> tuple[HeaderGround | None, dict[str, np.ndarray]]:
    """`header["ground"]` and the arrays for `ground` (None and none on the plane)."""
    present = [part for part in ground.meshes() if part.recorded]
    if not present:
        return None, {}
    arrays: dict[str, np.ndarray] = {}
    entries: list[GroundMeshEntry] = []
    for part in present:
        name, mesh = part.name, part.mesh
        entries.append(
            {
                "name": name,
                "vertices": len(mesh.vertices),
                "triangles": len(mesh.triangles),
                "rgb": [round(float(c), 6) for c in part.rgb],
            }
        )
        arrays[array_name(name, "points")] = mesh.vertices.astype("<f4")
        arrays[array_name(name, "normals")] = mesh.normals.astype("<f4")
        arrays[array_name(name, "triangles")] = mesh.triangles.astype("<u4")
    return {"digest": ground.digest(), "meshes": entries}, arrays


def entries(header: dict[str, Any]) -> list[GroundMeshEntry]:
    """The meshes `header` declares (none on the plane); the header must be sound."""
    ground = header.get(KEY)
    return [] if ground is None else list(ground["meshes"])


def problem(header: dict[str, object]) -> str | None:
    """The first problem of `header["ground"]`, or None."""
    ground = header.get(KEY)
    if ground is None:
        return None
    if not isinstance(ground, dict) or set(ground) != {"digest", "meshes"}:
        return f"header.{KEY}: must be null or an object with digest and meshes"
    if not isinstance(ground["digest"], str):
        return f"header.{KEY}.digest: must be a string"
    meshes = ground["meshes"]
    if not isinstance(meshes, list) or not 1 <= len(meshes) <= MAX_MESHES:
        return f"header.{KEY}.meshes: must list 1 to {MAX_MESHES} meshes"
    seen = set()
    for i, mesh in enumerate(meshes):
        where = f"header.{KEY}.meshes[{i}]"
        if not isinstance(mesh, dict) or set(mesh) - {"rgb"} != {"name", "vertices", "triangles"}:
            return f"{where}: must be an object with name, vertices, triangles (and rgb)"
        if not isinstance(mesh["name"], str) or not _NAME.fullmatch(mesh["name"]):
            return f"{where}.name: must be an identifier (letters, digits, _; at most 40)"
        if mesh["name"] in seen:
            return f"{where}.name: {mesh['name']!r} is used twice"
        if "rgb" in mesh and not _is_colour(mesh["rgb"]):  # absent in older takes
            return f"{where}.rgb: must be three numbers in [0, 1]"
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


def _is_colour(rgb: object) -> bool:
    """Three finite numbers in [0, 1] (display rgb)."""
    return (
        isinstance(rgb, list)
        and len(rgb) == 3
        and all(isinstance(c, (int, float)) and not isinstance(c, bool) for c in rgb)
        and all(0.0 <= c <= 1.0 and math.isfinite(c) for c in rgb)  # range first: an int
    )  # too large for a float is compared exactly, never converted


def shapes(header: dict[str, object]) -> dict[str, tuple[int, ...]]:
    """Array name -> shape for a sound header."""
    out: dict[str, tuple[int, ...]] = {}
    for mesh in entries(header):
        for part, _, width in PARTS:
            rows = mesh["triangles"] if part == "triangles" else mesh["vertices"]
            out[array_name(mesh["name"], part)] = (rows, width)
    return out


def dtypes(header: dict[str, object]) -> dict[str, np.dtype[np.generic]]:
    """Array name -> dtype, in file order, for a sound header."""
    return {
        array_name(mesh["name"], part): np.dtype(dtype)
        for mesh in entries(header)
        for part, dtype, _ in PARTS
    }


def index_problem(header: dict[str, object], arrays: dict[str, np.ndarray]) -> str | None:
    """A triangle index at or past its mesh's vertex count, or None."""
    for mesh in entries(header):
        name = array_name(mesh["name"], "triangles")
        triangles = arrays.get(name)
        if triangles is not None and len(triangles) and int(triangles.max()) >= mesh["vertices"]:
            return f"{name}: index {int(triangles.max())} past the {mesh['vertices']} vertices"
    return None


def colours(header: dict[str, object]) -> dict[str, tuple[float, float, float]]:
    """Mesh name -> its colour (display rgb) for the meshes a sound header gives one
    (takes before meshes carried their colour give none)."""
    return {
        mesh["name"]: (float(mesh["rgb"][0]), float(mesh["rgb"][1]), float(mesh["rgb"][2]))
        for mesh in entries(header)
        if "rgb" in mesh
    }


def meshes_of(
    header: dict[str, object], arrays: dict[str, np.ndarray]
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
