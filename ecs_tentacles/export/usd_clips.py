"""Creatures that replay one gait clip all take long share its SkelAnimation.

    clips = SharedClips(pxr, layer, source, plans)     # who shares, the clips' prims
    clips.bind(name, creature)                          # a sharer's animation: a reference
    for first, chunk in source.chunks():
        origin, yaw = clips.add(first, chunk.frames)    # the sharers' root motion samples

A take of a crowd with level of detail records a replayed creature as what it is
(take format version 2, `ReplaySegment`): clip `clip`'s `kind` loop (idle or crawl) at
phase `phase + (f - first) * rate` on frame f, carried by a ground frame (`replay_xy`,
`replay_heading`). A creature whose whole take is one such stretch moves exactly as
the clip does, shifted in time and carried over the ground. UsdSkel's instancing
pattern says it in USD: one SkelAnimation per (clip, kind) of the clip itself, the
rest state shared (the body plan's, `ecs_tentacles.export.usd_plans`), and per creature
an animation prim that is an internal reference to the clip's with a time offset:

    /World/<clips>                           class (abstract: not drawn, not imported)
      /plan<p>_clip<i>_<kind>                class SkelAnimation: joints; rotations and
                                             translations at clip frame k at time code
                                             k / rate, the loop repeated to cover the
                                             take once; scales constant
    /World/<c>/<c>_skeleton/<c>_animation    def SkelAnimation, references the clip's
                                             with Sdf.LayerOffset(-phase / rate): take
                                             frame f shows clip phase `phase + f * rate`
    /World/<c>                               SkelRoot: translate (X, Y, 0) and rotateZ
                                             (heading, degrees, unwrapped) sampled

Between clip frames USD interpolates the joints' local rotations (slerp) where the take
blends the clip's body poses (positions lerped, rotations nlerped): joints agree within
millimetres. A creature physical at any frame, or that switches clip or kind, keeps
its own animation (`ecs_tentacles.export.usd_joint_samples`), its replayed frames
filled in by the take.

Reads the take's replay segments and clips; writes prims and samples on the layer.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ecs_tentacles.export.names import part
from ecs_tentacles.export.usd_layer import StreamedLayer
from ecs_tentacles.export.usd_plans import BodyPlan
from ecs_tentacles.skin.streamed import JointRotations

KINDS = ("idle", "crawl")  # replay_kind 0 and 1
FOLDER = "clips"


@dataclass(frozen=True)
class Sharer:
    """A creature that shares a clip's animation: which one, and its time offset."""

    creature: int
    animation: str  # the clip animation's prim path
    offset: float  # take frames: Sdf.LayerOffset(offset) on its reference


class SharedClips:
    """The clip animations creatures share, and those creatures' root motion."""

    def __init__(self, pxr: Any, layer: StreamedLayer, source: Any, plans: list[BodyPlan]):
        self.pxr, self.layer, self.source = pxr, layer, source
        header = source.header
        names = [c["name"] for c in header["creatures"]]
        self.folder = _folder(set(names))
        plan_of = {c: plan for plan in plans for c in plan.members.tolist()}
        self.sharers: dict[int, Sharer] = {}
        made: dict[tuple[int, int, float], str] = {}
        for creature in range(len(names)):
            segments = source.segments(creature)
            if len(segments) != 1:
                continue
            seg = segments[0]
            plan = plan_of[creature]
            if (seg.first, seg.end) != (0, source.frames) or seg.rate <= 0:
                continue
            key = (int(seg.clip), int(seg.kind), float(seg.rate))
            if key not in made:
                made[key] = self._define(plan, plans.index(plan), *key)
            phase = float(seg.phase) % self._loop_frames(seg.clip, seg.kind)  # in [0, F)
            self.sharers[creature] = Sharer(creature, made[key], -phase / float(seg.rate))
        self.order = sorted(self.sharers)
        self.xy = np.zeros((source.frames, len(self.order), 2))
        self.heading = np.zeros((source.frames, len(self.order)))
        for column, creature in enumerate(self.order):
            xy, heading = source.root_motion(creature)
            self.xy[:, column] = xy
            self.heading[:, column] = np.unwrap(heading)
        Sdf = pxr.Sdf
        self.translates = [Sdf.Path(f"/World/{names[c]}.xformOp:translate") for c in self.order]
        self.turns = [Sdf.Path(f"/World/{names[c]}.xformOp:rotateZ") for c in self.order]

    def _loop_frames(self, clip: int, kind: int) -> int:
        """Frames in clip `clip`'s `kind` loop."""
        return int(self.source.header["replay"]["clips"][clip]["frames"][kind])

    def _define(self, plan: BodyPlan, index: int, clip: int, kind: int, rate: float) -> str:
        """The clip's SkelAnimation (abstract), sampled at its own frames over the take."""
        pxr, layer = self.pxr, self.layer
        Vt, UsdSkel = pxr.Vt, pxr.UsdSkel
        frames = self._loop_frames(clip, kind)
        start = 0 if kind == 0 else self._loop_frames(clip, 0)
        poses = self.source.clip_pose(clip)  # (F_idle + F_crawl, B, 7) ground frame
        count = math.ceil((self.source.frames - 1) * rate + frames) + 1  # the take, once
        rows = start + np.arange(count) % frames
        rotations = JointRotations(plan.skeleton.parents, np.arange(poses.shape[1])[None])
        local = rotations.local(poses[rows, :, 3:7])[:, 0]  # (count, J, 4)
        xyzw = np.ascontiguousarray(local[..., [1, 2, 3, 0]], dtype=np.float32)
        translations = np.broadcast_to(
            plan.skeleton.rest_translation.astype(np.float32), (count, *local.shape[1:2], 3)
        ).copy()
        translations[:, 0] = poses[rows, 0, :3]  # the mantle in the ground frame
        path = f"/World/{self.folder}/plan{index}_clip{clip}_{KINDS[kind]}"
        layer.stage.CreateClassPrim(f"/World/{self.folder}")  # abstract: nothing to draw
        prim = layer.stage.CreateClassPrim(path)
        prim.SetTypeName("SkelAnimation")
        anim = UsdSkel.Animation(prim)
        anim.CreateJointsAttr(plan.arrays["joints"])
        anim.CreateScalesAttr(plan.arrays["scales"])
        rotation_path = anim.CreateRotationsAttr().GetPath()
        translation_path = anim.CreateTranslationsAttr().GetPath()
        with layer.batch():
            for j in range(count):
                time = j / rate
                layer.sample(rotation_path, time, Vt.QuatfArray.FromNumpy(xyzw[j]), xyzw[j].nbytes)
                value = Vt.Vec3fArray.FromNumpy(translations[j])
                layer.sample(translation_path, time, value, translations[j].nbytes)
        return path

    def bind(self, name: str, creature: int) -> bool:
        """Creature `name` (number `creature`) animated by its shared clip, with its
        offset; False when it does not share (its own animation is written)."""
        sharer = self.sharers.get(creature)
        if sharer is None:
            return False
        Sdf, UsdGeom = self.pxr.Sdf, self.pxr.UsdGeom
        stage = self.layer.stage
        anim = stage.GetPrimAtPath(
            f"/World/{name}/{part(name, 'skeleton')}/{part(name, 'animation')}"
        )
        anim.GetReferences().AddInternalReference(
            Sdf.Path(sharer.animation), Sdf.LayerOffset(sharer.offset, 1.0)
        )
        root = UsdGeom.Xformable(stage.GetPrimAtPath(f"/World/{name}"))
        root.AddRotateZOp()  # after the translate: turn in place, then move
        return True

    def add(self, first: int, frames: int) -> tuple[np.ndarray, np.ndarray]:
        """The sharers' root motion at frames [first, first + frames): translate and
        rotateZ samples; returns their origins (n, S, 3) and yaws (n, S) in `order`."""
        Gf = self.pxr.Gf
        xy = self.xy[first : first + frames]
        heading = self.heading[first : first + frames]
        degrees = np.degrees(heading).tolist()
        rows = xy.tolist()
        with self.layer.batch():
            for row in range(frames):
                frame = first + row
                for column, (translate, turn) in enumerate(
                    zip(self.translates, self.turns, strict=True)
                ):
                    x, y = rows[row][column]
                    self.layer.sample(translate, frame, Gf.Vec3d(x, y, 0.0), 24)
                    self.layer.sample(turn, frame, degrees[row][column], 4)
        origin = np.zeros((frames, len(self.order), 3))
        origin[..., :2] = xy
        return origin, heading


def _folder(names: set[str]) -> str:
    """`clips`, or `clips_1` (`_2`, ...) if a creature is called that."""
    folder, k = FOLDER, 0
    while folder in names:
        k += 1
        folder = f"{FOLDER}_{k}"
    return folder
