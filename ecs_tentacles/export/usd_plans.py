"""Body plans of a skinned USD: creatures built alike share one rest state.

    plans = body_plans(take.header, detail)         # creatures grouped by body plan
    define_creature(pxr, stage, plan, name, colour, materials, turns)

Creatures with the same mantle and links (sizes, tentacle count and angles) share a
skeleton bound at the origin and one mesh (`ecs_tentacles.skin`): their USD arrays
(joints, bind and rest transforms, the animation's constant translations and scales,
the mesh's points, normals, faces, UVs and skin weights) are made once per plan and set
on every creature of it. VtArrays share their data, so the layer holds one copy, and a
`.usdc` stores equal arrays once: a crowd of one body plan pays for one mesh.

`define_creature` makes one creature's prims (SkelRoot, Skeleton, SkelAnimation, skinned
Mesh, material) as `ecs_tentacles.export.skinned_usd` lays them out, `define_skin` a
Skeleton with its animation and skin (a replayed stretch's: `usd_clips`); the time
samples are `ecs_tentacles.export.usd_joint_samples`'. Reads the take's header; writes prims on
the stage it is given.
"""

from __future__ import annotations

from dataclasses import dataclass
from types import ModuleType
from typing import TYPE_CHECKING, Any

import numpy as np

from ecs_tentacles.export.materials import bind_usd, usd_material
from ecs_tentacles.export.names import part
from ecs_tentacles.export.usd_pxr import usd_modules
from ecs_tentacles.skin.mesh import Detail, SkinMesh, creature_mesh
from ecs_tentacles.skin.skeleton import Skeleton, build_skeleton, creature_layout, transforms

if TYPE_CHECKING:
    from pxr import Usd, Vt


@dataclass(frozen=True)
class BodyPlan:
    """Creatures built alike (the same mantle and links): one skeleton at the origin and
    one mesh, their USD arrays made once; `bodies` (C, J) each creature's joint bodies."""

    skeleton: Skeleton
    mesh: SkinMesh
    names: list[str]
    members: np.ndarray  # (C,) the creatures' indices in the take
    bodies: np.ndarray
    arrays: dict[str, object]


def body_plans(header: dict[str, Any], detail: Detail | None = None) -> list[BodyPlan]:
    """The take's creatures grouped by body plan, in the order plans first appear."""
    pxr = usd_modules()
    grouped: dict[tuple[object, ...], list[int]] = {}
    layouts = [creature_layout(header, c) for c in range(len(header["creatures"]))]
    for index, (layout, _) in enumerate(layouts):
        key = (layout.mantle_radius, layout.mantle_height) + tuple(
            (t.angle, tuple(t.lengths.tolist()), tuple(t.radii.tolist())) for t in layout.tentacles
        )
        grouped.setdefault(key, []).append(index)
    plans = []
    for members in grouped.values():
        layout, bodies = layouts[members[0]]
        skeleton = build_skeleton(layout, bodies)  # bound at the origin: the plan's
        mesh = creature_mesh(skeleton, detail)
        plans.append(
            BodyPlan(
                skeleton=skeleton,
                mesh=mesh,
                names=[header["creatures"][c]["name"] for c in members],
                members=np.array(members, dtype=np.int64),
                bodies=np.stack([layouts[c][1] for c in members]),
                arrays=_plan_arrays(pxr, skeleton, mesh),
            )
        )
    return plans


def _matrices(pxr: ModuleType, matrices: np.ndarray) -> Vt.Matrix4dArray:
    # USD matrices act on row vectors: store the transpose of the column-vector form
    return pxr.Vt.Matrix4dArray.FromNumpy(np.ascontiguousarray(np.swapaxes(matrices, -1, -2)))


def _plan_arrays(pxr: ModuleType, skeleton: Skeleton, mesh: SkinMesh) -> dict[str, object]:
    """The USD arrays every creature of a plan holds: made once, set on each (VtArrays
    share their data: the layer holds one copy)."""
    Gf, Vt = pxr.Gf, pxr.Vt
    joints = len(skeleton.names)
    rest = transforms(skeleton.rest_rotation, skeleton.rest_translation)
    low, high = mesh.positions.min(axis=0), mesh.positions.max(axis=0)
    return {
        "joints": Vt.TokenArray(skeleton.names),
        "joint_names": Vt.TokenArray(skeleton.leaf_names),
        "bind": _matrices(pxr, skeleton.bind),
        "rest": _matrices(pxr, rest),
        "translations": Vt.Vec3fArray.FromNumpy(skeleton.rest_translation.astype(np.float32)),
        "scales": Vt.Vec3hArray.FromNumpy(np.ones((joints, 3), np.float16)),
        "points": Vt.Vec3fArray.FromNumpy(mesh.positions.astype(np.float32)),
        "counts": Vt.IntArray.FromNumpy(np.full(len(mesh.faces), 3, np.int32)),
        "indices": Vt.IntArray.FromNumpy(mesh.faces.reshape(-1).astype(np.int32)),
        "normals": Vt.Vec3fArray.FromNumpy(mesh.normals.astype(np.float32)),
        "extent": Vt.Vec3fArray([Gf.Vec3f(*low.tolist()), Gf.Vec3f(*high.tolist())]),
        "st": Vt.Vec2fArray.FromNumpy(mesh.uv.reshape(-1, 2).astype(np.float32)),
        "joint_indices": Vt.IntArray.FromNumpy(mesh.joints.reshape(-1).astype(np.int32)),
        "joint_weights": Vt.FloatArray.FromNumpy(mesh.weights.reshape(-1).astype(np.float32)),
    }


def define_creature(
    pxr: ModuleType,
    stage: Usd.Stage,
    plan: BodyPlan,
    name: str,
    colour: np.ndarray,
    folder: str,
    turns: bool = False,
) -> None:
    """Creature `name`'s prims: SkelRoot (its root motion: a translate op, float3, and
    with `turns` a rotateZ op after it), its own Skeleton, SkelAnimation (constant
    channels set; rotations sampled by `ecs_tentacles.export.usd_joint_samples`) and
    skinned Mesh, its material."""
    root = pxr.UsdSkel.Root.Define(stage, f"/World/{name}")
    root.AddTranslateOp(pxr.UsdGeom.XformOp.PrecisionFloat)  # sampled: the mantle's place
    if turns:
        root.AddRotateZOp()  # after the translate: turned in place, then moved
    define_skin(pxr, stage, plan, name, name, colour, folder, own_animation=True)


def define_skin(
    pxr: ModuleType,
    stage: Usd.Stage,
    plan: BodyPlan,
    name: str,
    prefix: str,
    colour: np.ndarray,
    folder: str,
    own_animation: bool,
) -> tuple[str, str]:
    """A Skeleton `<prefix>_skeleton` with its SkelAnimation `<prefix>_animation` and the
    skinned Mesh `<prefix>_skin` bound to it, under creature `name`'s SkelRoot, in its
    material. With `own_animation` the animation's constant channels are set; else it is
    left empty, for a reference to a shared clip's (`ecs_tentacles.export.usd_clips`).
    Returns the paths of the skeleton and the skin."""
    Gf, Sdf, UsdGeom, UsdSkel = pxr.Gf, pxr.Sdf, pxr.UsdGeom, pxr.UsdSkel
    arrays = plan.arrays
    base = f"/World/{name}"
    skel = UsdSkel.Skeleton.Define(stage, f"{base}/{part(prefix, 'skeleton')}")
    skel.CreateJointsAttr(arrays["joints"])
    skel.CreateJointNamesAttr(arrays["joint_names"])
    skel.CreateBindTransformsAttr(arrays["bind"])
    skel.CreateRestTransformsAttr(arrays["rest"])

    anim = UsdSkel.Animation.Define(stage, f"{skel.GetPath()}/{part(prefix, 'animation')}")
    if own_animation:  # a local opinion would hide a referenced clip's samples
        anim.CreateJointsAttr(arrays["joints"])
        anim.CreateTranslationsAttr(arrays["translations"])
        anim.CreateScalesAttr(arrays["scales"])
        anim.CreateRotationsAttr()
    binding = UsdSkel.BindingAPI.Apply(skel.GetPrim())
    binding.CreateAnimationSourceRel().SetTargets([anim.GetPath()])

    skin = UsdGeom.Mesh.Define(stage, f"{base}/{part(prefix, 'skin')}")
    skin.CreateSubdivisionSchemeAttr(UsdGeom.Tokens.none)
    skin.CreatePointsAttr(arrays["points"])
    skin.CreateFaceVertexCountsAttr(arrays["counts"])
    skin.CreateFaceVertexIndicesAttr(arrays["indices"])
    skin.CreateNormalsAttr(arrays["normals"])
    skin.SetNormalsInterpolation(UsdGeom.Tokens.vertex)
    skin.CreateExtentAttr(arrays["extent"])
    primvars = UsdGeom.PrimvarsAPI(skin.GetPrim())
    st = primvars.CreatePrimvar(
        "st", Sdf.ValueTypeNames.TexCoord2fArray, UsdGeom.Tokens.faceVarying
    )
    st.Set(arrays["st"])
    bound = UsdSkel.BindingAPI.Apply(skin.GetPrim())
    bound.CreateSkeletonRel().SetTargets([skel.GetPath()])
    bound.CreateJointIndicesPrimvar(False, 2).Set(arrays["joint_indices"])
    bound.CreateJointWeightsPrimvar(False, 2).Set(arrays["joint_weights"])
    bound.CreateGeomBindTransformAttr(Gf.Matrix4d(1.0))
    material = usd_material(pxr, stage, folder, name, colour)
    bind_usd(pxr, skin.GetPrim(), material, colour)
    return str(skel.GetPath()), str(skin.GetPath())
