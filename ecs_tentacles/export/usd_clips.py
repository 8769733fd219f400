"""Replayed stretches of creatures share one SkelAnimation per body plan, clip and kind.

    clips = SharedClips(pxr, layer, source, plans)     # the stretches; the shared prims
    clips.bind(name, creature)                          # a creature's stretches' skeletons
    clips.timeline                                      # which frames its own skeleton shows

A take of a crowd with level of detail records a replayed creature as what it is
(take format version 2, `ReplaySegment`): over a stretch of frames [first, end), clip
`clip`'s `kind` loop (idle or crawl) at clip frame `phase + (f - first) * rate` on frame
f, carried by a ground frame (`replay_xy`, `replay_heading`). UsdSkel's instancing
pattern says so in USD: the rest state shared (the body plan's,
`ecs_tentacles.export.usd_plans`), one SkelAnimation per (body plan, clip, kind) holding
the clip's own frames, and per stretch a Skeleton (with its skinned Mesh) whose
animation is an internal reference to the shared one, offset and scaled in time:

    /World/<clips>                           class (abstract: not drawn, not imported)
      /plan<p>_clip<i>_<kind>                class SkelAnimation: joints, translations,
                                             scales constant; rotations at clip frames
                                             lo..hi (the loop unrolled as far as the
                                             take's stretches reach), the root's in the
                                             clip's ground frame
    /World/<c>                               SkelRoot: translate (the mantle's position)
                                             and rotateZ (its ground frame's heading,
                                             degrees, unwrapped) sampled every frame
      /<c>_skeleton, /<c>_skin               its own: physical frames (`usd_joint_samples`)
      /<c>_replay<k>_skeleton                stretch k: its animation references the
        /<c>_replay<k>_animation             shared one with Sdf.LayerOffset(offset,
      /<c>_replay<k>_skin                    scale): take frame t is clip frame
                                             (t - offset) / scale = phase + (t - first) * rate

Each skeleton and its skin are visible only on their frames (`visibility` keyed:
invisible, inherited where they take over), so a USD client shows one of a creature's
skeletons at a time, the one that poses it as the take does. The own skeleton's
rotations are sampled only at the creature's physical frames and the frame after each
run of them (so that between that run's last frame and the next, where it is still
shown, USD interpolates towards the take's pose). A clip's phase starts anywhere in its
loop, so each stretch's start is taken modulo the loop's length: the shared animation
holds the clip frames from the lowest start to the furthest end (plus a rate's worth,
for the frame after a stretch's last), whatever the take's length in loops.

The clip's poses are the take's own (`ecs_tentacles.take.replay.blend`) at whole clip
frames; a take whose phases fall between clip frames is interpolated by USD (slerp of
local rotations where the take nlerps world ones: a small difference). Reads the take's
replay records and clips; writes prims and their (few) time samples on the layer.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from types import ModuleType
from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.export.names import part
from ecs_tentacles.export.take_chunks import ChunkSource
from ecs_tentacles.export.usd_layer import StreamedLayer
from ecs_tentacles.export.usd_plans import BodyPlan, define_skin
from ecs_tentacles.skin.streamed import JointRotations
from ecs_tentacles.take.replay import blend
from ecs_tentacles.take.stream import ReplaySegment

if TYPE_CHECKING:
    from pxr import Usd

KINDS = ("idle", "crawl")  # replay_kind 0 and 1
FOLDER = "clips"


@dataclass(frozen=True)
class Stretch(ReplaySegment):
    """Creature `creature`'s replay segment (frames [first, end): clip `clip`'s `kind`
    loop at clip frame `phase + (f - first) * rate`, `phase` taken into the loop's first
    turn), on the shared animation at `path`."""

    creature: int
    path: str


@dataclass(frozen=True)
class Timeline:
    """Per take frame and creature: `own` (frames, C) where its own skeleton shows,
    `heading` (frames, C) its ground frame's yaw (radians) where a stretch shows (NaN
    elsewhere); `turns` (C,) creatures with stretches (their SkelRoot has a rotateZ)."""

    own: np.ndarray
    heading: np.ndarray
    turns: np.ndarray

    @property
    def samples(self) -> np.ndarray:
        """(frames, C) the frames the own animation is sampled at: its own, and the
        frame after each run of them (frame 0 for a creature with none: a value)."""
        out = self.own.copy()
        out[1:] |= self.own[:-1]
        if len(out):
            out[0, ~out.any(axis=0)] = True
        return out


@dataclass
class Shared:
    """One shared animation: its path, plan, clip, kind and the clip frames it holds."""

    path: str
    plan: BodyPlan
    clip: int
    kind: int
    low: int
    high: int


class SharedClips:
    """The shared animations of a take's replayed stretches and who shows what when."""

    def __init__(
        self, pxr: ModuleType, layer: StreamedLayer, source: ChunkSource, plans: list[BodyPlan]
    ) -> None:
        self.pxr, self.layer, self.source = pxr, layer, source
        header = source.header
        names = [c["name"] for c in header["creatures"]]
        self.folder = _folder(set(names))
        frames, count = source.frames, len(names)
        own = np.ones((frames, count), dtype=bool)
        heading = np.full((frames, count), np.nan)
        self.stretches: dict[int, list[Stretch]] = {}
        self.plan_of: dict[int, BodyPlan] = {}
        self.shared: dict[tuple[int, int, int], Shared] = {}
        for p, plan in enumerate(plans):
            for creature in plan.members.tolist():
                segments = [s for s in source.segments(creature) if s.end > s.first]
                if not segments:
                    continue
                pose = source.clip_pose(segments[0].clip)
                if pose.shape[1] != plan.bodies.shape[1]:
                    continue  # a clip not of its plan's bodies: its own animation shows all
                _, turn = source.root_motion(creature)
                mine = []
                for segment in segments:
                    loop = int(header["replay"]["clips"][segment.clip]["frames"][segment.kind])
                    phase = segment.phase - loop * math.floor(segment.phase / loop)
                    shared = self._shared(p, plan, segment.clip, segment.kind)
                    # the last frame's clip frame, and a rate's worth after it
                    reach = phase + (segment.end - segment.first) * segment.rate
                    shared.low = min(shared.low, math.floor(phase))
                    shared.high = max(shared.high, math.ceil(reach))
                    fields = {**vars(segment), "phase": phase}
                    mine.append(Stretch(**fields, creature=creature, path=shared.path))
                    own[segment.first : segment.end, creature] = False
                    heading[segment.first : segment.end, creature] = turn[
                        segment.first : segment.end
                    ]
                self.stretches[creature] = mine
                self.plan_of[creature] = plan
        turns = np.zeros(count, dtype=bool)
        turns[list(self.stretches)] = True
        self.timeline = Timeline(own=own, heading=heading, turns=turns)
        for shared in self.shared.values():
            self._define(shared)

    def _shared(self, p: int, plan: BodyPlan, clip: int, kind: int) -> Shared:
        """The shared animation of plan `p`'s clip `clip`, kind `kind` (made on first ask)."""
        key = (p, clip, kind)
        if key not in self.shared:
            path = f"/World/{self.folder}/plan{p}_clip{clip}_{KINDS[kind]}"
            self.shared[key] = Shared(path, plan, clip, kind, low=2**62, high=-(2**62))
        return self.shared[key]

    def _define(self, shared: Shared) -> None:
        """The shared SkelAnimation (abstract), sampled at clip frames low..high."""
        pxr, layer, source = self.pxr, self.layer, self.source
        Vt, UsdSkel = pxr.Vt, pxr.UsdSkel
        counts = tuple(source.header["replay"]["clips"][shared.clip]["frames"])
        phase = np.arange(shared.low, shared.high + 1, dtype=np.float64)
        kind = np.full(len(phase), shared.kind, dtype=np.int64)
        poses = blend(source.clip_pose(shared.clip), counts, kind, phase)  # ground frame
        joints = np.arange(poses.shape[1])[None]
        local = JointRotations(shared.plan.skeleton.parents, joints).local(poses[:, :, 3:])
        xyzw = np.ascontiguousarray(local[:, 0][..., [1, 2, 3, 0]], dtype=np.float32)
        layer.stage.CreateClassPrim(f"/World/{self.folder}")  # abstract: nothing to draw
        prim = layer.stage.CreateClassPrim(shared.path)
        prim.SetTypeName("SkelAnimation")
        anim = UsdSkel.Animation(prim)
        anim.CreateJointsAttr(shared.plan.arrays["joints"])
        anim.CreateTranslationsAttr(shared.plan.arrays["translations"])
        anim.CreateScalesAttr(shared.plan.arrays["scales"])
        rotations = anim.CreateRotationsAttr().GetPath()
        with layer.batch():
            for row, frame in enumerate(range(shared.low, shared.high + 1)):
                value = Vt.QuatfArray.FromNumpy(xyzw[row])
                layer.sample(rotations, frame, value, xyzw[row].nbytes)

    def bind(self, name: str, creature: int, colour: np.ndarray, materials: str) -> None:
        """Creature `name`'s (number `creature`) skeletons of its stretches, each bound to
        its shared animation offset in time, shown on its frames; its own skeleton shown
        on the others. Nothing for a creature without stretches."""
        mine = self.stretches.get(creature)
        if not mine:
            return
        pxr = self.pxr
        Sdf, stage, plan = pxr.Sdf, self.layer.stage, self.plan_of[creature]
        own = self.timeline.own[:, creature]
        base = f"/World/{name}"
        _show(pxr, stage, [f"{base}/{part(name, 'skeleton')}", f"{base}/{part(name, 'skin')}"],
              own)  # fmt: skip
        for k, stretch in enumerate(mine):
            prefix = part(name, f"replay{k}")
            skeleton, skin = define_skin(pxr, stage, plan, name, prefix, colour, materials, False)
            anim = stage.GetPrimAtPath(f"{skeleton}/{part(prefix, 'animation')}")
            offset = Sdf.LayerOffset(stretch.first - stretch.phase / stretch.rate, 1 / stretch.rate)
            anim.GetReferences().AddInternalReference(Sdf.Path(stretch.path), offset)
            shown = np.zeros(len(own), dtype=bool)
            shown[stretch.first : stretch.end] = True
            _show(pxr, stage, [skeleton, skin], shown)

    @property
    def sharing(self) -> int:
        """Creatures with a replayed stretch."""
        return len(self.stretches)


def _show(pxr: ModuleType, stage: Usd.Stage, paths: list[str], shown: np.ndarray) -> None:
    """Key the visibility of the prims at `paths`: inherited on the frames `shown` (bool
    per frame), invisible on the others; keys only where it changes (and at frame 0)."""
    UsdGeom = pxr.UsdGeom
    changes = np.flatnonzero(np.diff(shown.astype(np.int8))) + 1
    frames = [0, *changes.tolist()]
    tokens = (UsdGeom.Tokens.invisible, UsdGeom.Tokens.inherited)
    for path in paths:
        attr = UsdGeom.Imageable(stage.GetPrimAtPath(path)).CreateVisibilityAttr()
        for frame in frames:
            attr.Set(tokens[int(shown[frame])], frame)


def _folder(names: set[str]) -> str:
    """`clips`, or `clips_1` (`_2`, ...) if a creature is called that."""
    folder, k = FOLDER, 0
    while folder in names:
        k += 1
        folder = f"{FOLDER}_{k}"
    return folder
