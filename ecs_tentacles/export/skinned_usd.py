"""Take -> USD stage with skinned creatures (UsdSkel), the form artists animate; streamed.

    /World                                   Xform, the default prim
      /<c>                                   SkelRoot (c: the creature's name): the root
                                             motion, xformOp:translate (float3) sampled
                                             (the mantle's position), and for a creature
                                             that replays a clip xformOp:rotateZ (its
                                             heading); visibility keyed where it came or
                                             went
        /<c>_skeleton                        Skeleton: joints (mantle/t0_link0/...),
                                             bindTransforms, restTransforms (its body
                                             plan's, at the origin); for a creature that
                                             replays, shown on its physical frames only
          /<c>_animation                     SkelAnimation: rotations sampled (the root's:
                                             the mantle's rotation, seen from the heading
                                             where there is one) at the frames this
                                             skeleton needs; translations and scales
                                             constant (one value, not samples)
        /<c>_skin                            Mesh (bound to the skeleton): points in the
                                             bind pose, normals, primvars:st (faceVarying),
                                             primvars:skel:jointIndices / jointWeights (2),
                                             bound to /World/materials/<c>_material
        /<c>_replay<k>_skeleton, _skin       replayed stretch k: a Skeleton and its skin,
          /<c>_replay<k>_animation           shown on the stretch's frames, the animation
                                             an internal reference to /World/clips/...
                                             offset in time (`usd_clips`)
        /<c>_suckers/<c>_t<k>/<c>_t<k>_link<i>/<c>_t<k>_link<i>_sucker<n>
                                             locator (`locators=True`): Xform, translate
                                             sampled (the sucker point), `ecs:attached`
        /<c>_goals/<c>_goal<j>               goal locators (`locators=True`), translate
                                             sampled (`usd_tracks`)
        /<c>_fur/<c>_guides                  fur guides: BasisCurves in the mantle's frame,
                                             the folder following the mantle (`usd_curves`)
                                             Below the SkelRoot, so in its moving frame
                                             (`root_frames`): USD and Blender both put
                                             them back where the take has them
      /clips/plan<p>_clip<i>_<kind>          class SkelAnimations the stretches share
      /materials/<c>_material                each creature's material, its sandbox colour
                                             (`ecs_tentacles.export.materials`)

What is constant is written once. Links do not stretch: a joint's translation in its
parent is the rest offset at every frame (MuJoCo's hinges sit at fixed points of the
parent body), so the animation's translations (and scales, 1) are one value each, and
the root's motion is the SkelRoot's transform: the animation samples only
rotations. The SkelRoot's translate is float3: a 30 m crowd's positions are then
within 4 micrometres. Creatures of one body plan (the same mantle and links) share
their rest state: skeleton, bind pose and mesh are the same arrays, held once in memory
and stored once in a `.usdc` (USD's crate files keep one copy of equal arrays).
UsdSkel poses a mesh point as `S(t) * sum_i w_i inv(bind_i) joint_i(t) p` with S the
Skeleton's world transform (its ancestors' included), so the mesh is bound at the
origin and moves with S. The motion is on the SkelRoot, not the Skeleton: Blender's
importer (5.0.1) moves the armature with an animated SkelRoot, while with the motion on
the Skeleton the creatures came in out of place and torn. That importer does not bring
USD's animated visibility along either: there a replayed creature's skeletons (its own
and its stretches') all stay shown, each posed right on its own frames; the add-on
(`ecs-tentacles blender-addon`) is Blender's way in for such crowds.

Streamed: the take is read a chunk of frames at a time (`TakeChunks`, or a take file
opened for streaming), each chunk's rotations made for every creature of a body plan
at once (`ecs_tentacles.skin.streamed`) and written as time samples; a `.usdc` is
saved as it grows (`ecs_tentacles.export.usd_layer`), so memory does not grow with
the take. With reduced keys each chunk is reduced on its own (its first and last
frames kept), so the error stays within the tolerance across chunks.

A SkelAnimation samples all its joints at once, so with reduced keys its time samples
are the frames where any joint has a key (each joint's value there comes from its own
reduced curve). Stage settings as in the rigid form: upAxis Z, metersPerUnit 1,
time code i = frame i.
"""

from __future__ import annotations

import importlib
import os
from collections.abc import Callable
from types import ModuleType
from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.export.ground import write_usd_ground
from ecs_tentacles.export.materials import take_colours, usd_folder
from ecs_tentacles.export.names import unique_path
from ecs_tentacles.export.root_frames import RootFrames
from ecs_tentacles.export.take_chunks import ChunkSource, TakeChunks, frame_slice
from ecs_tentacles.export.usd import _pxr, mark_rate, set_timing, static_take
from ecs_tentacles.export.usd_clips import SharedClips, Timeline
from ecs_tentacles.export.usd_joint_samples import PlanSamples, key_report
from ecs_tentacles.export.usd_layer import StreamedLayer
from ecs_tentacles.export.usd_plans import body_plans, define_creature
from ecs_tentacles.export.usd_tracks import Steps, UsdTracks, Visibility, key_steps
from ecs_tentacles.numeric.quaternions import quat_rotate
from ecs_tentacles.output.atomic import atomic_output
from ecs_tentacles.skin.keys import KeyReport
from ecs_tentacles.skin.rig import Skin
from ecs_tentacles.take import Take
from ecs_tentacles.take.header_entries import HeaderBody, HeaderSucker

if TYPE_CHECKING:
    from pxr import Usd

Progress = Callable[[int], object]
WORK_BYTES = 32 * 1024**2  # joint rotations (float64) worked on at once: chunks are split


def write_skinned_usd(
    take: Take | ChunkSource,
    path: str | os.PathLike[str],
    skin: Skin | None = None,
    locators: bool = False,
    progress: Progress | None = None,
) -> KeyReport:
    """Write `take` (in memory, or a stream of chunks) as a skinned USD file (.usda, .usdc,
    .usd) atomically, a chunk of frames at a time; returns the keys. `skin`: the mesh's
    detail and the keys kept (None: `Skin()`'s defaults). With `locators`, suckers and
    goals are written too; `progress(n)` as n more frames are written."""
    source = TakeChunks(take) if isinstance(take, Take) else take
    with atomic_output(path) as temporary:
        layer = StreamedLayer(temporary)
        report = _fill(layer, source, skin or Skin(), locators, progress)
        layer.finish()
    return report


def build_skinned_stage(
    take: Take,
    skin: Skin | None = None,
    locators: bool = False,
    progress: Progress | None = None,
) -> tuple[Usd.Stage, KeyReport]:
    """An in-memory `Usd.Stage` with one SkelRoot per creature, and the key report."""
    layer = StreamedLayer(None)
    report = _fill(layer, TakeChunks(take), skin or Skin(), locators, progress)
    return layer.stage, report


def _fill(
    layer: StreamedLayer,
    source: ChunkSource,
    skin: Skin,
    locators: bool,
    progress: Progress | None,
) -> KeyReport:
    """Every prim of the take on `layer`'s stage, then its frames chunk by chunk."""
    pxr = _pxr()
    importlib.import_module("pxr.UsdSkel")  # the skel schemas, into the `pxr` namespace
    importlib.import_module("pxr.UsdShade")
    stage, header = layer.stage, source.header
    set_timing(stage, source.fps, source.frames)
    stage.SetDefaultPrim(pxr.UsdGeom.Xform.Define(stage, "/World").GetPrim())
    still = static_take(source)
    colours, folder = take_colours(still), usd_folder(still)
    plans = body_plans(header, skin.detail)
    clips = SharedClips(pxr, layer, source, plans)
    plan_of = {name: plan for plan in plans for name in plan.names}
    names = [c["name"] for c in header["creatures"]]
    turns = clips.timeline.turns.tolist()
    for creature, name in enumerate(names):  # in the take's order
        define_creature(pxr, stage, plan_of[name], name, colours[name], folder, turns[creature])
        clips.bind(name, creature, colours[name], folder)
        mark_rate(stage, f"/World/{name}", source.fps, source.frames)
    visibility = Visibility(layer, [f"/World/{name}" for name in names])
    suckers = Suckers(pxr, layer, header["suckers"], header["bodies"]) if locators else None
    tracks = UsdTracks(layer, header, source.static, locators, relative=True)
    write_usd_ground(pxr, stage, still)
    animated = [
        PlanSamples(pxr, layer, plan, skin.keys, source.frames, clips.timeline) for plan in plans
    ]
    rows = max(1, WORK_BYTES // (32 * max(1, len(header["bodies"]))))
    for first, chunk in source.chunks(**_posed(animated, suckers, clips.timeline)):
        for start in range(0, chunk.frames, rows):
            end = min(start + rows, chunk.frames)
            piece = chunk if end - start == chunk.frames else frame_slice(chunk, start, end)
            origin = np.zeros((piece.frames, len(names), 3))
            yaw = np.zeros((piece.frames, len(names)))
            for samples in animated:  # each creature's root motion as written
                members = samples.plan.members
                origin[:, members], yaw[:, members] = samples.add(first + start, piece)
            roots = RootFrames(origin, yaw if clips.sharing else None)
            if suckers is not None:
                suckers.add(first + start, piece, roots)
            visibility.add(first + start, piece)
            tracks.add(first + start, piece, roots)
        layer.flush()
        if progress is not None:
            progress(chunk.frames)
    stretches = sum(len(s) for s in clips.stretches.values())
    return key_report(
        animated, source.frames, len(names), clips.sharing, len(clips.shared), stretches
    )


def _posed(
    animated: list[PlanSamples], suckers: Suckers | None, timeline: Timeline
) -> dict[str, np.ndarray]:
    """What the writers read of a replayed creature's frames, for `TakeSource.chunks`:
    every frame its mantle (root motion, carried curves) and sucker links (locators),
    its whole pose only where its own skeleton is sampled. Reduced keys read every
    frame's whole pose: all bodies then."""
    if any(samples.keys.mode != "all" for samples in animated):
        return {}
    mantles = [samples.plan.bodies[:, 0] for samples in animated]
    links = [] if suckers is None else [suckers.bodies]
    return {"bodies": np.unique(np.concatenate([*mantles, *links])), "whole": timeline.samples}


class Suckers:
    """Every sucker as a locator: translate sampled (the sucker point, in its creature's
    root frame), `ecs:attached` keyed."""

    def __init__(
        self,
        pxr: ModuleType,
        layer: StreamedLayer,
        suckers: list[HeaderSucker],
        bodies: list[HeaderBody],
    ) -> None:
        Gf, Sdf, UsdGeom = pxr.Gf, pxr.Sdf, pxr.UsdGeom
        self.Gf, self.layer = Gf, layer
        stage = layer.stage
        self.bodies = np.array([s["body"] for s in suckers], dtype=np.int64)
        owner = [bodies[body]["creature"] for body in self.bodies.tolist()]
        self.owners = np.array(owner, dtype=np.int64)
        self.offsets = np.array([s["offset"] for s in suckers], dtype=np.float64)
        self.translates, self.attached = [], []
        for sucker in suckers:
            creature, _, rest = sucker["name"].split("/", 2)
            path = f"/World/{unique_path(f'{creature}/suckers/{rest}')}"
            parts = path.split("/")
            for depth in range(4, len(parts)):
                UsdGeom.Xform.Define(stage, "/".join(parts[:depth]))
            xform = UsdGeom.Xform.Define(stage, path)
            self.translates.append(xform.AddTranslateOp().GetAttr().GetPath())
            attached = xform.GetPrim().CreateAttribute("ecs:attached", Sdf.ValueTypeNames.Bool)
            self.attached.append(attached.GetPath())
        self.steps = Steps()

    def add(self, first: int, chunk: Take, roots: RootFrames) -> None:
        """The chunk's sucker points (in their creature's root frame) and attachments."""
        if not len(self.bodies):
            return
        quat = chunk.quat[:, self.bodies].astype(np.float64)
        points = chunk.pos[:, self.bodies] + quat_rotate(quat, self.offsets)
        rows = roots.local(points, self.owners).tolist()
        with self.layer.batch():
            for row, frame_points in enumerate(rows):
                for path, point in zip(self.translates, frame_points, strict=True):
                    self.layer.sample(path, first + row, self.Gf.Vec3d(*point), 24)
            key_steps(self.layer, self.attached, self.steps, first, chunk.sucker_attached)
