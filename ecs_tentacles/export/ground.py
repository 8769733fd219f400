"""The ground of a take (`Take.ground_meshes`: terrain and obstacles) in USD and glTF.

USD: an Xform `/World/terrain` holding a Mesh per ground mesh (`surface`: the
heightfield, `obstacles`: every obstacle), normals per vertex, a display colour and a
bound UsdPreviewSurface (`/World/terrain/terrain_materials/<mesh>_material`, its shader
`<mesh>_material_shader`: no prim name twice in the file, as the creatures' parts).
glTF: a node `terrain` with a child node per mesh (`terrain/surface`,
`terrain/obstacles`), each with a mesh and a material of the same colour. A take
recorded on the plane has neither. If a creature is called `terrain`, the ground's root
is `terrain_ground` instead.

Colours are the sandbox's (each mesh's `rgb` in the take, display sRGB; `EARLIER` for
takes written before meshes carried it) as linear light (`colours.to_linear`), the
space USD's colours and glTF's `baseColorFactor` are in, as
the creatures' materials are: an importer shows the ground the sandbox drew.
"""

from __future__ import annotations

from collections.abc import Callable
from types import ModuleType
from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.export.materials import shader_name
from ecs_tentacles.skin.colours import to_linear
from ecs_tentacles.take import Take

if TYPE_CHECKING:
    from ecs_tentacles.export.glb import GlbBuffer
    from ecs_tentacles.export.gltf_types import Material, Mesh, Node, Primitive

EXPORT_NAMES = {"terrain": "surface", "obstacles": "obstacles"}
ROUGHNESS = 0.9


# colours of takes written before a take's ground meshes carried theirs (the terrain
# plugin's sand and rock), and of a mesh with neither
EARLIER = {"terrain": (0.62, 0.56, 0.44), "obstacles": (0.50, 0.50, 0.52)}
GREY = (0.5, 0.5, 0.5)


def linear_colour(take: Take, name: str) -> list[float]:
    """Ground mesh `name`'s colour as the sandbox draws it, in linear light (rgb)."""
    rgb = take.ground_colours().get(name) or EARLIER.get(name, GREY)
    return [float(v) for v in to_linear(rgb)]


def root_name(take: Take) -> str:
    """`terrain`, unless a creature has that name."""
    names = {creature["name"] for creature in take.header["creatures"]}
    return "terrain" if "terrain" not in names else "terrain_ground"


def write_usd_ground(pxr: ModuleType, stage: object, take: Take) -> None:
    """The take's ground meshes under `/World/<root_name>` (nothing on the plane)."""
    meshes = take.ground_meshes()
    if not meshes:
        return
    import importlib

    importlib.import_module("pxr.UsdShade")
    Gf, Sdf, UsdGeom, UsdShade, Vt = pxr.Gf, pxr.Sdf, pxr.UsdGeom, pxr.UsdShade, pxr.Vt
    base = f"/World/{root_name(take)}"
    UsdGeom.Xform.Define(stage, base)
    folder = f"{base}/{root_name(take)}_materials"
    UsdGeom.Scope.Define(stage, folder)
    for name, mesh in meshes:
        label = EXPORT_NAMES.get(name, name)
        prim = UsdGeom.Mesh.Define(stage, f"{base}/{label}")
        prim.CreateSubdivisionSchemeAttr(UsdGeom.Tokens.none)
        points = np.asarray(mesh.vertices, dtype=np.float32)
        prim.CreatePointsAttr(Vt.Vec3fArray.FromNumpy(points))
        counts = np.full(len(mesh.triangles), 3, np.int32)
        prim.CreateFaceVertexCountsAttr(Vt.IntArray.FromNumpy(counts))
        indices = np.asarray(mesh.triangles, dtype=np.int32).reshape(-1)
        prim.CreateFaceVertexIndicesAttr(Vt.IntArray.FromNumpy(indices))
        prim.CreateNormalsAttr(Vt.Vec3fArray.FromNumpy(np.asarray(mesh.normals, np.float32)))
        prim.SetNormalsInterpolation(UsdGeom.Tokens.vertex)
        low, high = points.min(axis=0), points.max(axis=0)
        prim.CreateExtentAttr([Gf.Vec3f(*low.tolist()), Gf.Vec3f(*high.tolist())])
        colour = Gf.Vec3f(*linear_colour(take, name))
        prim.CreateDisplayColorAttr([colour])
        path = f"{folder}/{label}_material"
        material = UsdShade.Material.Define(stage, path)
        shader = UsdShade.Shader.Define(stage, f"{path}/{shader_name(f'{label}_material')}")
        shader.CreateIdAttr("UsdPreviewSurface")
        shader.CreateInput("diffuseColor", Sdf.ValueTypeNames.Color3f).Set(colour)
        shader.CreateInput("roughness", Sdf.ValueTypeNames.Float).Set(ROUGHNESS)
        shader.CreateInput("metallic", Sdf.ValueTypeNames.Float).Set(0.0)
        material.CreateSurfaceOutput().ConnectToSource(shader.ConnectableAPI(), "surface")
        UsdShade.MaterialBindingAPI.Apply(prim.GetPrim()).Bind(material)


def add_gltf_ground(
    take: Take,
    buffer: GlbBuffer,
    nodes: list[Node],
    meshes: list[Mesh],
    materials: list[Material],
    to_y_up: Callable[[np.ndarray], np.ndarray],
) -> None:
    """Append the ground's node (and its meshes and materials), a child of the document's
    first node (both writers' scene root); nothing for a take without ground meshes."""
    found = take.ground_meshes()
    if not found:
        return
    root = root_name(take)
    holder = len(nodes)
    nodes.append({"name": root, "children": []})
    for name, mesh in found:
        label = EXPORT_NAMES.get(name, name)
        materials.append(
            {
                "name": f"{root}/{label}",
                "pbrMetallicRoughness": {
                    "baseColorFactor": [*linear_colour(take, name), 1.0],
                    "metallicFactor": 0.0,
                    "roughnessFactor": ROUGHNESS,
                },
            }
        )
        positions = to_y_up(np.asarray(mesh.vertices, np.float64)).astype(np.float32)
        normals = to_y_up(np.asarray(mesh.normals, np.float64)).astype(np.float32)
        attributes = {
            "POSITION": buffer.add(positions, "VEC3", 34962),
            "NORMAL": buffer.add(normals, "VEC3", 34962),
        }
        indices = buffer.add(np.asarray(mesh.triangles, np.uint32).reshape(-1), "SCALAR", 34963)
        primitive: Primitive = {
            "attributes": attributes,
            "indices": indices,
            "material": len(materials) - 1,
            "mode": 4,
        }
        meshes.append({"name": f"{root}/{label}", "primitives": [primitive]})
        nodes[holder]["children"].append(len(nodes))
        nodes.append({"name": f"{root}/{label}", "mesh": len(meshes) - 1})
    nodes[0]["children"].append(holder)
