"""Creatures that replay one gait clip from the same start share one SkelAnimation.

    clips = SharedClips(pxr, layer, source, plans)     # who shares; the shared prims
    clips.bind(name, creature)                          # a sharer's animation: a reference
    for first, chunk in source.chunks():
        origin, yaw = clips.add(first, frames)          # the sharers' root motion samples

A take of a crowd with level of detail records a replayed creature as what it is
(take format version 2, `ReplaySegment`): clip `clip`'s `kind` loop (idle or crawl) at
phase `phase + (f - first) * rate` on frame f, carried by a ground frame (`replay_xy`,
`replay_heading`). Such a creature moves as the clip does, carried over the ground.
UsdSkel's instancing pattern says so in USD: the rest state shared (the body plan's,
`ecs_tentacles.export.usd_plans`), one SkelAnimation per group of creatures that move
alike in their own frames, and per creature an animation prim that is an internal
reference to it, its root motion on its SkelRoot:

    /World/<clips>                           class (abstract: not drawn, not imported)
      /plan<p>_clip<i>_<kind>_<g>            class SkelAnimation: joints, scales
                                             constant; rotations and translations (the
                                             root's, in the ground frame) every frame
    /World/<c>/<c>_skeleton/<c>_animation    def SkelAnimation: references the group's
    /World/<c>                               SkelRoot: translate (X, Y, 0) and rotateZ
                                             (heading, degrees, unwrapped) sampled

Who shares: a creature with one replayed stretch that lasts to the take's end, of one
clip and kind. A take's frame 0 is the pose the scene was built in, so every stretch
starts at frame 1 or later and the frames before it are physical: the group's
animation holds them too (the first member's, in its own frame: the mantle's position
and heading), and a creature joins only if its frames before the stretch are that
pose in its frame (within `PREFIX_TOLERANCE`: a crowd built alike and replayed from
frame 1). A group is (body plan, clip, kind, rate, the frame the stretch starts, its
phase there): a time offset on the reference (`Sdf.LayerOffset`) cannot shift a
creature whose first frames are not the clip's, so the members of a group start
together and the reference has no offset. Crowds replay from one phase (every
creature demoted at frame 1 starts the crawl at the same clip frame), so one group
holds them all. The group's animation is sampled at every take frame from the clip as
the take blends it (`ecs_tentacles.take.replay.blend`: positions lerped, rotations
nlerped), so its joints are the take's at every frame; between frames USD slerps.

A creature physical after its first frames, or that switches clip or kind, keeps its
own animation (`ecs_tentacles.export.usd_joint_samples`), its replayed frames filled
in by the take. Reads the take's replay records, clips and first chunk; writes prims
and time samples on the layer.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ecs_tentacles.export.names import part
from ecs_tentacles.export.take_chunks import ChunkSource
from ecs_tentacles.export.usd_layer import StreamedLayer
from ecs_tentacles.export.usd_plans import BodyPlan
from ecs_tentacles.skin.streamed import JointRotations
from ecs_tentacles.take import Take
from ecs_tentacles.take.replay import blend

KINDS = ("idle", "crawl")  # replay_kind 0 and 1
FOLDER = "clips"
PREFIX_TOLERANCE = 1e-4  # m: a body's distance from the group's before the stretch


@dataclass
class Group:
    """Creatures that move alike in their own frames: the shared animation's path, its
    plan, and the segment they replay (first frame, clip, kind, phase there, rate)."""

    path: str
    plan: BodyPlan
    first: int
    clip: int
    kind: int
    phase: float
    rate: float
    members: list[int]
    prefix: np.ndarray  # (first, B, 7) the first member's bodies before the stretch


class SharedClips:
    """The shared animations of a take's replayed creatures, and their root motion."""

    def __init__(
        self, pxr: Any, layer: StreamedLayer, source: ChunkSource, plans: list[BodyPlan]
    ) -> None:
        self.pxr, self.layer, self.source = pxr, layer, source
        names = [c["name"] for c in source.header["creatures"]]
        self.folder = _folder(set(names))
        self.sharers: dict[int, Group] = {}
        self.order: list[int] = []
        candidates = self._candidates(plans)
        if not candidates:
            return
        _, opening = next(iter(source.chunks()))  # the frames before every stretch
        groups: dict[tuple[Any, ...], Group] = {}
        self.xy = np.zeros((source.frames, 0, 2))
        columns_xy, columns_heading = [], []
        for creature, (plan, segment) in candidates.items():
            if segment.first > opening.frames:
                continue
            xy, heading = (np.array(a, dtype=np.float64) for a in source.root_motion(creature))
            prefix, xy[: segment.first], heading[: segment.first] = _own_frames(
                opening, plan, plan.bodies[list(plan.members).index(creature)], segment.first
            )
            key = (id(plan), segment.clip, segment.kind, segment.rate, segment.first,
                   round(segment.phase, 9))  # fmt: skip
            group = groups.get(key)
            if group is None:
                group = groups[key] = Group(
                    path=f"/World/{self.folder}/plan{plans.index(plan)}_clip{segment.clip}"
                    f"_{KINDS[segment.kind]}_{len(groups)}",
                    plan=plan, first=segment.first, clip=segment.clip, kind=segment.kind,
                    phase=segment.phase, rate=segment.rate, members=[], prefix=prefix,
                )  # fmt: skip
            elif len(prefix) and _apart(prefix, group.prefix) > PREFIX_TOLERANCE:
                continue  # its first frames are its own: it keeps its own animation
            group.members.append(creature)
            self.sharers[creature] = group
            self.order.append(creature)
            columns_xy.append(xy)
            columns_heading.append(np.unwrap(heading))
        if not self.order:
            return
        self.xy = np.stack(columns_xy, axis=1)  # (frames, sharers, 2)
        self.heading = np.stack(columns_heading, axis=1)
        for group in groups.values():
            if group.members:
                self._define(group)
        Sdf = pxr.Sdf
        self.translates = [Sdf.Path(f"/World/{names[c]}.xformOp:translate") for c in self.order]
        self.turns = [Sdf.Path(f"/World/{names[c]}.xformOp:rotateZ") for c in self.order]

    def _candidates(self, plans: list[BodyPlan]) -> dict[int, tuple[BodyPlan, Any]]:
        """Creatures with one replayed stretch lasting to the end, of a clip of their
        plan's bodies: (plan, segment) by creature."""
        out = {}
        for plan in plans:
            for creature in plan.members.tolist():
                segments = self.source.segments(creature)
                if len(segments) != 1 or segments[0].end != self.source.frames:
                    continue
                pose = self.source.clip_pose(segments[0].clip)
                if pose.shape[1] == plan.bodies.shape[1]:
                    out[creature] = (plan, segments[0])
        return out

    def _define(self, group: Group) -> None:
        """The group's SkelAnimation (abstract), sampled at every take frame."""
        pxr, layer, source = self.pxr, self.layer, self.source
        Vt, UsdSkel = pxr.Vt, pxr.UsdSkel
        frames = source.frames
        counts = tuple(source.header["replay"]["clips"][group.clip]["frames"])
        later = np.arange(group.first, frames)
        phase = group.phase + (later - group.first) * group.rate
        kind = np.full(len(later), group.kind, dtype=np.int64)
        clip = blend(source.clip_pose(group.clip), counts, kind, phase)
        poses = np.concatenate([group.prefix, clip])  # (frames, B, 7) in its own frame
        rotations = JointRotations(group.plan.skeleton.parents, np.arange(poses.shape[1])[None])
        local = rotations.local(poses[:, :, 3:])[:, 0]  # (frames, J, 4)
        xyzw = np.ascontiguousarray(local[..., [1, 2, 3, 0]], dtype=np.float32)
        rest = group.plan.skeleton.rest_translation.astype(np.float32)
        translations = np.broadcast_to(rest, (frames, *rest.shape)).copy()
        translations[:, 0] = poses[:, 0, :3]  # the mantle in the creature's own frame
        layer.stage.CreateClassPrim(f"/World/{self.folder}")  # abstract: nothing to draw
        prim = layer.stage.CreateClassPrim(group.path)
        prim.SetTypeName("SkelAnimation")
        anim = UsdSkel.Animation(prim)
        anim.CreateJointsAttr(group.plan.arrays["joints"])
        anim.CreateScalesAttr(group.plan.arrays["scales"])
        rotation_path = anim.CreateRotationsAttr().GetPath()
        translation_path = anim.CreateTranslationsAttr().GetPath()
        with layer.batch():
            for frame in range(frames):
                value = Vt.QuatfArray.FromNumpy(xyzw[frame])
                layer.sample(rotation_path, frame, value, xyzw[frame].nbytes)
                value = Vt.Vec3fArray.FromNumpy(translations[frame])
                layer.sample(translation_path, frame, value, translations[frame].nbytes)

    def bind(self, name: str, creature: int) -> bool:
        """Creature `name` (number `creature`) animated by its group's animation; False
        when it does not share (its own animation is written)."""
        group = self.sharers.get(creature)
        if group is None:
            return False
        Sdf, UsdGeom = self.pxr.Sdf, self.pxr.UsdGeom
        stage = self.layer.stage
        skeleton = f"/World/{name}/{part(name, 'skeleton')}"
        anim = stage.GetPrimAtPath(f"{skeleton}/{part(name, 'animation')}")
        anim.GetReferences().AddInternalReference(Sdf.Path(group.path))
        root = UsdGeom.Xformable(stage.GetPrimAtPath(f"/World/{name}"))
        root.AddRotateZOp()  # after the translate: turned in place, then moved
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
                paths = zip(self.translates, self.turns, strict=True)
                for column, (translate, turn) in enumerate(paths):
                    x, y = rows[row][column]
                    self.layer.sample(translate, frame, Gf.Vec3d(x, y, 0.0), 24)
                    self.layer.sample(turn, frame, degrees[row][column], 4)
        origin = np.zeros((frames, len(self.order), 3))
        origin[..., :2] = xy
        return origin, heading


def _own_frames(
    opening: Take, plan: BodyPlan, bodies: np.ndarray, first: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A creature's frames before its stretch in its own frame (the mantle's ground
    position and heading): (poses (first, B, 7), xy (first, 2), heading (first,))."""
    pos = opening.pos[:first, bodies].astype(np.float64)
    quat = opening.quat[:first, bodies].astype(np.float64)
    quat /= np.sqrt(np.einsum("fbi,fbi->fb", quat, quat))[..., None]
    w, x, y, z = np.moveaxis(quat[:, 0], -1, 0)
    heading = np.arctan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))  # the mantle's
    xy = pos[:, 0, :2]
    c, s = np.cos(heading)[:, None], np.sin(heading)[:, None]
    dx, dy = pos[..., 0] - xy[:, :1], pos[..., 1] - xy[:, 1:]
    out = np.empty((first, len(bodies), 7))
    out[..., 0] = c * dx + s * dy  # turned by -heading
    out[..., 1] = -s * dx + c * dy
    out[..., 2] = pos[..., 2]
    hc, hs = np.cos(0.5 * heading)[:, None], np.sin(0.5 * heading)[:, None]
    qw, qx, qy, qz = np.moveaxis(quat, -1, 0)  # (cos h/2, 0, 0, -sin h/2) * q
    out[..., 3] = hc * qw + hs * qz
    out[..., 4] = hc * qx + hs * qy
    out[..., 5] = hc * qy - hs * qx
    out[..., 6] = hc * qz - hs * qw
    return out, xy, heading


def _apart(a: np.ndarray, b: np.ndarray) -> float:
    """The largest distance between two creatures' bodies (poses (F, B, 7)), their
    links' far ends included (a rotation shows at the end of a link)."""
    far = np.linalg.norm(a[..., :3] - b[..., :3], axis=-1).max(initial=0.0)
    turned = np.abs(np.einsum("fbi,fbi->fb", a[..., 3:], b[..., 3:])).clip(0.0, 1.0)
    angle = 2.0 * np.arccos(turned).max(initial=0.0)
    return float(far + 0.1 * angle)  # a 10 cm link turned by `angle` moves its end this much


def _folder(names: set[str]) -> str:
    """`clips`, or `clips_1` (`_2`, ...) if a creature is called that."""
    folder, k = FOLDER, 0
    while folder in names:
        k += 1
        folder = f"{FOLDER}_{k}"
    return folder
