"""The ground of a take on terrain (`ecs_tentacles.take.ground`): its meshes in Blender.

`header["ground"]["meshes"]` lists up to 8 meshes (name, vertices, triangles, rgb), each
stored as `ground_<name>_points` (n, 3) float32 and `ground_<name>_triangles` (m, 3)
uint32. They come in as the USD import shows them (`ecs_tentacles.export.ground`): an
empty `terrain` (`terrain_ground` beside a creature called `terrain`) holding a mesh
object per ground mesh (`surface`: the heightfield, `obstacles`), each with a material
`<mesh>_material` of the sandbox's colour (linear). `meshes(header)` reads the entries
(numpy only); `make(...)` builds them (bpy).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from .header import TakeFileError

if TYPE_CHECKING:
    import bpy

    from .reader import TakeFile

MAX_MESHES = 8
MAX_VERTICES = 1025 * 1025 * 4
NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]{0,39}")
NAMES = {"terrain": "surface", "obstacles": "obstacles"}  # as the USD export names them
# the terrain plugin's sand and rock (takes written before meshes carried their colour)
EARLIER = {"terrain": (0.62, 0.56, 0.44), "obstacles": (0.50, 0.50, 0.52)}
ROUGHNESS = 0.9


@dataclass(frozen=True)
class GroundMesh:
    """One ground mesh as the header lists it (`rgb`: display colour, 0..1)."""

    name: str
    vertices: int
    triangles: int
    rgb: tuple[float, float, float]


def meshes(header: dict[str, object]) -> list[GroundMesh]:
    """The ground meshes `header` lists (none on the plane); `TakeFileError` (one line)
    for an unsound entry."""
    ground = header.get("ground")
    if ground is None:
        return []
    listed = ground.get("meshes") if isinstance(ground, dict) else None
    if not isinstance(listed, list) or not 1 <= len(listed) <= MAX_MESHES:
        raise TakeFileError(f"header.ground.meshes: must list 1 to {MAX_MESHES} meshes")
    out: list[GroundMesh] = []
    for i, mesh in enumerate(listed):
        where = f"header.ground.meshes[{i}]"
        name = mesh.get("name") if isinstance(mesh, dict) else None
        if not isinstance(name, str) or not NAME.fullmatch(name) or name in {m.name for m in out}:
            raise TakeFileError(f"{where}.name: must be a unique identifier, got {name!r}")
        sizes = [mesh.get(key) for key in ("vertices", "triangles")]
        if not all(
            isinstance(n, int) and not isinstance(n, bool) and 1 <= n <= 2 * MAX_VERTICES
            for n in sizes
        ):
            raise TakeFileError(f"{where}: vertices and triangles must be whole numbers >= 1")
        rgb = mesh.get("rgb", EARLIER.get(name, (0.5, 0.5, 0.5)))
        if not isinstance(rgb, (list, tuple)) or len(rgb) != 3 or not all(
            isinstance(c, (int, float)) and not isinstance(c, bool) and math.isfinite(c)
            and 0 <= c <= 1 for c in rgb
        ):  # fmt: skip
            raise TakeFileError(f"{where}.rgb: must be three numbers in [0, 1]")
        out.append(GroundMesh(name, sizes[0], sizes[1], (rgb[0], rgb[1], rgb[2])))
    return out


def make(take: TakeFile, collection: bpy.types.Collection) -> int:
    """The take's ground meshes in `collection` under their empty (see the module);
    returns how many. `take` is an open `reader.TakeFile`."""
    import bpy

    from .shared import module

    listed = meshes(take.header)
    if not listed:
        return 0
    names = {c.name for c in take.creatures}
    root = bpy.data.objects.new("terrain" if "terrain" not in names else "terrain_ground", None)
    collection.objects.link(root)
    to_linear = module("skin_colours").to_linear
    for mesh in listed:
        points = take.static(f"ground_{mesh.name}_points", (mesh.vertices, 3), "<f4")
        triangles = take.static(f"ground_{mesh.name}_triangles", (mesh.triangles, 3), "<u4")
        if int(triangles.max()) >= mesh.vertices:
            raise TakeFileError(
                f"{take.path}: ground_{mesh.name}_triangles: index {int(triangles.max())}"
                f" past the {mesh.vertices} vertices"
            )
        name = NAMES.get(mesh.name, mesh.name)
        data = bpy.data.meshes.new(name)
        data.vertices.add(mesh.vertices)
        data.vertices.foreach_set("co", points.astype(np.float32).ravel())
        data.loops.add(3 * mesh.triangles)
        data.loops.foreach_set("vertex_index", triangles.astype(np.int32).ravel())
        data.polygons.add(mesh.triangles)
        data.polygons.foreach_set("loop_start", np.arange(0, 3 * mesh.triangles, 3, dtype=np.int32))
        data.update()
        data.shade_smooth()
        material = bpy.data.materials.new(f"{name}_material")
        linear = [*to_linear(mesh.rgb).tolist(), 1.0]
        material.diffuse_color = linear
        material.roughness = ROUGHNESS
        shader = next(n for n in material.node_tree.nodes if n.type == "BSDF_PRINCIPLED")
        shader.inputs["Base Color"].default_value = linear
        shader.inputs["Roughness"].default_value = ROUGHNESS
        data.materials.append(material)
        made = bpy.data.objects.new(name, data)
        made.parent = root
        collection.objects.link(made)
    return len(listed)
