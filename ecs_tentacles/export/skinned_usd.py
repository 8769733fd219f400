"""Take -> USD stage with skinned creatures (UsdSkel), the form artists animate.

    /World                                   Xform, the default prim
      /<c>                                   SkelRoot (c: the creature's name)
        /<c>_skeleton                        Skeleton: joints (mantle/t0_link0/...),
                                             bindTransforms (world), restTransforms (local)
          /<c>_animation                     SkelAnimation: rotations, translations
                                             (time-sampled), scales (constant 1)
        /<c>_skin                            Mesh (bound to the skeleton): points in the
                                             bind pose, normals, primvars:st (faceVarying),
                                             primvars:skel:jointIndices / jointWeights (2),
                                             bound to /World/materials/<c>_material
        /<c>_suckers/<c>_t<k>/<c>_t<k>_link<i>/<c>_t<k>_link<i>_sucker<n>
                                             locator (`locators=True`): Xform, translate
                                             sampled (the sucker point), `ecs:attached`
        /<c>_goals/<c>_goal<j>, /<c>_fur/... the take's tracks, as in the rigid form
                                             (`ecs_tentacles.export.usd`); the goals only
                                             with `locators=True`
      /materials/<c>_material                each creature's material, its sandbox colour
                                             (`ecs_tentacles.export.materials`)

A SkelAnimation samples all its joints at once, so with reduced keys its time samples
are the frames where any joint has a key (each joint's value there comes from its own
reduced curve). Stage settings as in the rigid form: upAxis Z, metersPerUnit 1,
time code i = frame i.
"""

from __future__ import annotations

import importlib
import os
from collections.abc import Callable
from typing import Any

import numpy as np

from ecs_tentacles.export.ground import write_usd_ground
from ecs_tentacles.export.materials import bind_usd, take_colours, usd_folder, usd_material
from ecs_tentacles.export.names import part, unique_path
from ecs_tentacles.export.usd import _pxr, key_visibility, mark_rate, new_stage, write_tracks
from ecs_tentacles.numeric.quaternions import quat_rotate
from ecs_tentacles.output.atomic import atomic_output
from ecs_tentacles.skin.keys import KeyReport
from ecs_tentacles.skin.mesh import Detail
from ecs_tentacles.skin.rig import Keys, SkinnedCreature, skinned_creatures
from ecs_tentacles.skin.skeleton import transforms
from ecs_tentacles.take import Take


def write_skinned_usd(
    take: Take,
    path: str | os.PathLike[str],
    detail: Detail | None = None,
    keys: Keys | None = None,
    locators: bool = False,
    progress: Callable[[int], object] | None = None,
) -> KeyReport:
    """Write `take` as a skinned USD file (.usda, .usdc, .usd) atomically; returns the keys.
    With `locators`, suckers and goals are written too; `progress(1)` after each creature."""
    stage, report = build_skinned_stage(take, detail, keys, locators, progress)
    with atomic_output(path) as temporary:
        if not stage.GetRootLayer().Export(str(temporary)):
            raise OSError(f"{path}: USD could not write the file")
    return report


def build_skinned_stage(
    take: Take,
    detail: Detail | None = None,
    keys: Keys | None = None,
    locators: bool = False,
    progress: Callable[[int], object] | None = None,
) -> tuple[Any, KeyReport]:
    """An in-memory `Usd.Stage` with one SkelRoot per creature, and the key report."""
    pxr = _pxr()
    importlib.import_module("pxr.UsdSkel")  # the skel schemas, into the `pxr` namespace
    importlib.import_module("pxr.UsdShade")

    UsdGeom = pxr.UsdGeom
    stage = new_stage(take)
    stage.SetDefaultPrim(UsdGeom.Xform.Define(stage, "/World").GetPrim())
    creatures, report = skinned_creatures(take, detail, keys)
    shown = take.visible()
    of_name = {c["name"]: i for i, c in enumerate(take.header["creatures"])}
    colours, folder = take_colours(take), usd_folder(take)
    for creature in creatures:
        name = creature.skeleton.layout.name
        _creature(pxr, stage, creature, colours[name], folder)
        mark_rate(stage, f"/World/{name}", take)
        key_visibility(stage, f"/World/{name}", shown[:, of_name[name]])
        if progress is not None:
            progress(1)
    if locators:
        for index, sucker in enumerate(take.header["suckers"]):
            _sucker(pxr, stage, take, index, sucker)
    write_tracks(pxr, stage, take, locators)
    write_usd_ground(pxr, stage, take)
    return stage, report


def _matrices(pxr: Any, matrices: np.ndarray) -> Any:
    # USD matrices act on row vectors: store the transpose of the column-vector form
    return pxr.Vt.Matrix4dArray.FromNumpy(np.ascontiguousarray(np.swapaxes(matrices, -1, -2)))


def _creature(
    pxr: Any, stage: Any, creature: SkinnedCreature, colour: np.ndarray, folder: str
) -> None:
    Gf, Sdf, UsdGeom, UsdSkel, Vt = pxr.Gf, pxr.Sdf, pxr.UsdGeom, pxr.UsdSkel, pxr.Vt
    skeleton, mesh = creature.skeleton, creature.mesh
    base = f"/World/{skeleton.layout.name}"
    UsdSkel.Root.Define(stage, base)
    name = skeleton.layout.name
    skel = UsdSkel.Skeleton.Define(stage, f"{base}/{part(name, 'skeleton')}")
    skel.CreateJointsAttr(skeleton.names)
    skel.CreateJointNamesAttr(skeleton.leaf_names)
    skel.CreateBindTransformsAttr(_matrices(pxr, skeleton.bind))
    rest = transforms(skeleton.rest_rotation, skeleton.rest_translation)
    skel.CreateRestTransformsAttr(_matrices(pxr, rest))

    anim = UsdSkel.Animation.Define(stage, f"{skel.GetPath()}/{part(name, 'animation')}")
    anim.CreateJointsAttr(skeleton.names)
    frames = creature.sample_frames
    rotations = creature.rotations_at(frames).astype(np.float32)
    translations = creature.translations_at(frames).astype(np.float32)
    rotation_attr = anim.CreateRotationsAttr()
    translation_attr = anim.CreateTranslationsAttr()
    for row, frame in enumerate(frames.tolist()):
        w, xyz = rotations[row, :, :1], rotations[row, :, 1:]
        rotation_attr.Set(Vt.QuatfArray.FromNumpy(np.concatenate([xyz, w], axis=1)), frame)
        translation_attr.Set(Vt.Vec3fArray.FromNumpy(translations[row]), frame)
    anim.CreateScalesAttr(Vt.Vec3hArray.FromNumpy(np.ones((len(skeleton.names), 3), np.float16)))
    binding = UsdSkel.BindingAPI.Apply(skel.GetPrim())
    binding.CreateAnimationSourceRel().SetTargets([anim.GetPath()])

    skin = UsdGeom.Mesh.Define(stage, f"{base}/{part(name, 'skin')}")
    skin.CreateSubdivisionSchemeAttr(UsdGeom.Tokens.none)
    skin.CreatePointsAttr(Vt.Vec3fArray.FromNumpy(mesh.positions.astype(np.float32)))
    skin.CreateFaceVertexCountsAttr(Vt.IntArray.FromNumpy(np.full(len(mesh.faces), 3, np.int32)))
    skin.CreateFaceVertexIndicesAttr(Vt.IntArray.FromNumpy(mesh.faces.reshape(-1).astype(np.int32)))
    skin.CreateNormalsAttr(Vt.Vec3fArray.FromNumpy(mesh.normals.astype(np.float32)))
    skin.SetNormalsInterpolation(UsdGeom.Tokens.vertex)
    low, high = mesh.positions.min(axis=0), mesh.positions.max(axis=0)
    skin.CreateExtentAttr([Gf.Vec3f(*low.tolist()), Gf.Vec3f(*high.tolist())])
    primvars = UsdGeom.PrimvarsAPI(skin.GetPrim())
    st = primvars.CreatePrimvar(
        "st", Sdf.ValueTypeNames.TexCoord2fArray, UsdGeom.Tokens.faceVarying
    )
    st.Set(Vt.Vec2fArray.FromNumpy(mesh.uv.reshape(-1, 2).astype(np.float32)))
    bound = UsdSkel.BindingAPI.Apply(skin.GetPrim())
    bound.CreateSkeletonRel().SetTargets([skel.GetPath()])
    bound.CreateJointIndicesPrimvar(False, 2).Set(
        Vt.IntArray.FromNumpy(mesh.joints.reshape(-1).astype(np.int32))
    )
    bound.CreateJointWeightsPrimvar(False, 2).Set(
        Vt.FloatArray.FromNumpy(mesh.weights.reshape(-1).astype(np.float32))
    )
    bound.CreateGeomBindTransformAttr(Gf.Matrix4d(1.0))
    material = usd_material(pxr, stage, folder, name, colour)
    bind_usd(pxr, skin.GetPrim(), material, colour)


def _sucker(pxr: Any, stage: Any, take: Take, index: int, sucker: dict[str, Any]) -> None:
    """The sucker point as a world-space sampled translate, under the creature's `suckers`."""
    Gf, Sdf, UsdGeom = pxr.Gf, pxr.Sdf, pxr.UsdGeom
    creature, _, rest = sucker["name"].split("/", 2)
    path = f"/World/{unique_path(f'{creature}/suckers/{rest}')}"
    parts = path.split("/")
    for depth in range(4, len(parts)):
        UsdGeom.Xform.Define(stage, "/".join(parts[:depth]))
    xform = UsdGeom.Xform.Define(stage, path)
    body = sucker["body"]
    quat = take.quat[:, body].astype(np.float64)
    points = take.pos[:, body] + quat_rotate(quat, np.asarray(sucker["offset"], np.float64))
    translate = xform.AddTranslateOp()
    for frame, point in enumerate(points.tolist()):
        translate.Set(Gf.Vec3d(*point), frame)
    attached = xform.GetPrim().CreateAttribute("ecs:attached", Sdf.ValueTypeNames.Bool)
    values = take.sucker_attached[:, index].tolist()
    for frame, value in enumerate(values):
        if frame == 0 or value != values[frame - 1]:
            attached.Set(value, frame)
