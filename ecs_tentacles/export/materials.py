"""Each creature's material in USD and glTF: its sandbox colour (`ecs_tentacles.skin.colours`).

The k-th creature of a take gets the sandbox's k-th colour, in a material named
`<c>_material` (`ecs_tentacles.export.names.part`): the skinned mesh (`<c>_skin`) and,
in the rigid form, the mantle and every capsule of the creature are bound to it.

    USD   /World/materials/<c>_material   UsdPreviewSurface (its shader
          .../<c>_material_shader)        diffuseColor (linear), roughness; the scope
                                          is `materials_1` if a creature is called
                                          `materials` (`usd_folder`)
    glTF  material <c>_material           rigid: baseColorFactor (linear); skinned: a
                                          texture of the colour (rings along the
                                          tentacle, a pale underside), a white factor

The material, its shader and the mesh have names of their own: importers with one
namespace for every prim (Blender's objects) rename a second `octopus_skin` to
`octopus_skin.001`.

Material colours are linear light (`to_linear`), textures sRGB, so an importer shows
the colour the sandbox drew.
"""

from __future__ import annotations

import io
from types import ModuleType
from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.export.names import part
from ecs_tentacles.skin.colours import PALE, creature_colour, look_in_take, to_linear
from ecs_tentacles.take import Take

if TYPE_CHECKING:
    from pxr import Usd, UsdShade

    from ecs_tentacles.export.gltf_types import Material, PbrMetallicRoughness

FOLDER = "materials"  # USD: the scope under /World holding the creatures' materials
ROUGHNESS = 0.6


def material_name(creature: str) -> str:
    """`<c>_material`: creature `creature`'s material (its mesh is `<c>_skin`)."""
    return part(creature, "material")


def shader_name(material: str) -> str:
    """`<material>_shader`: the UsdPreviewSurface shader of material `material`."""
    return f"{material}_shader"


def take_colours(take: Take) -> dict[str, np.ndarray]:
    """Each creature's display colour (rgb 0..1) in the sandbox's default (natural)
    palette, by name, in the take's order."""
    names = [str(c["name"]) for c in take.header["creatures"]]
    return {name: creature_colour(look_in_take(take.header, k)) for k, name in enumerate(names)}


def usd_folder(take: Take) -> str:
    """`/World/materials`, the scope of the creatures' materials; `/World/materials_1`
    (`_2`, ...) if a creature is called `materials` (its root prim is `/World/<c>`)."""
    names = {str(c["name"]) for c in take.header["creatures"]}
    folder, k = FOLDER, 0
    while folder in names:
        k += 1
        folder = f"{FOLDER}_{k}"
    return f"/World/{folder}"


def usd_material(
    pxr: ModuleType, stage: Usd.Stage, folder: str, creature: str, colour: np.ndarray
) -> UsdShade.Material:
    """`<folder>/<c>_material` (`folder`: `usd_folder(take)`), a UsdPreviewSurface of
    `colour` (display rgb): made once, returned again after."""
    Sdf, UsdShade = pxr.Sdf, pxr.UsdShade
    path = f"{folder}/{material_name(creature)}"
    if stage.GetPrimAtPath(path):
        return UsdShade.Material(stage.GetPrimAtPath(path))
    pxr.UsdGeom.Scope.Define(stage, folder)
    material = UsdShade.Material.Define(stage, path)
    shader = UsdShade.Shader.Define(stage, f"{path}/{shader_name(material_name(creature))}")
    shader.CreateIdAttr("UsdPreviewSurface")
    linear = pxr.Gf.Vec3f(*to_linear(colour).tolist())
    shader.CreateInput("diffuseColor", Sdf.ValueTypeNames.Color3f).Set(linear)
    shader.CreateInput("roughness", Sdf.ValueTypeNames.Float).Set(ROUGHNESS)
    shader.CreateInput("metallic", Sdf.ValueTypeNames.Float).Set(0.0)
    material.CreateSurfaceOutput().ConnectToSource(shader.ConnectableAPI(), "surface")
    return material


def bind_usd(pxr: ModuleType, prim: object, material: object, colour: np.ndarray) -> None:
    """Bind `material` to `prim` (a Gprim) and give it the same display colour."""
    linear = pxr.Gf.Vec3f(*to_linear(colour).tolist())
    pxr.UsdGeom.Gprim(prim).CreateDisplayColorAttr([linear])
    pxr.UsdShade.MaterialBindingAPI.Apply(prim).Bind(material)


def gltf_material(creature: str, colour: np.ndarray, texture: int | None = None) -> Material:
    """The glTF material of creature `creature`: its linear colour as the base colour
    factor, or with `texture` (a texture index of the colour) a white factor."""
    pbr: PbrMetallicRoughness = {"metallicFactor": 0.0, "roughnessFactor": ROUGHNESS}
    if texture is None:
        pbr["baseColorFactor"] = [*to_linear(colour).tolist(), 1.0]
    else:
        pbr["baseColorTexture"] = {"index": texture}
    return {"name": material_name(creature), "pbrMetallicRoughness": pbr}


def skin_texture(colour: np.ndarray, size: int = 64) -> bytes:
    """A PNG laid out on the tentacle UVs: `colour` (display rgb), rings along v, a pale
    underside (u from 0.75 to 1 is the strip facing down in the bind pose)."""
    from PIL import Image

    # image rows run top to bottom, glTF's v; the mesh's v (USD's) runs bottom to top
    u = (np.arange(size) + 0.5) / size
    v = (np.arange(size) + 0.5) / size
    rings = 0.9 + 0.1 * np.cos(2 * np.pi * 12 * v)[:, None]
    underside = np.clip(1 - np.abs(u - 0.875) / 0.125, 0.0, 1.0)[None, :] ** 0.5
    top, pale = np.asarray(colour, dtype=np.float64), np.asarray(PALE)
    shade = top + underside[..., None] * (pale - top)
    pixels = np.clip(255 * rings[..., None] * shade, 0, 255).astype(np.uint8)
    out = io.BytesIO()
    Image.fromarray(pixels[::-1], "RGB").save(out, format="PNG", optimize=False)
    return out.getvalue()
