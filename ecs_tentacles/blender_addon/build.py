"""A take opened in Blender (bpy): the importer's whole job, from the file to the scene.

    import_take(context, "crowd.npz", report)   # -> one line saying what was made

1. The file is read and checked (`reader`); nothing is made for a bad one.
2. Per body plan: an Armature and a Mesh datablock (`rig`), shared by its creatures.
3. The take is read a block of frames at a time (`stream`): every creature's ground
   frame (its armature object's keys), and the bone keys of the frames a creature was
   simulated (physical); replayed frames name a clip, its kind and phase instead.
4. Per creature: its objects and material (`rig`), an action of its root motion
   (`<c>_root`, the object's active action), and, in the NLA, a `physical` track with
   its own bone keys (`<c>_pose`, only for creatures simulated at some frame) under a
   `clips` track of strips of the shared clip actions (`clip<i>_<kind>`: one per clip
   and kind, every creature replaying it uses it, `motion.CLIP_KEYS` keys a clip frame,
   looping), one strip per replayed stretch, offset and scaled to its frames and phase.
5. The ground's meshes on terrain (`ground`), as the USD import shows them.
6. The scene takes the take's frame rate and range (frame i of the take is frame i).

`report(fraction, text)` is told of the progress (the operator shows it and prints a
line per tenth). Anything that fails half-way removes what was made.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from pathlib import Path

import bpy
import numpy as np

from . import ground, keys, rig
from .motion import CLIP_KEYS, Plan, Segment, clip_keys, continuous, rate_or_one, segments
from .reader import TakeFile, TakeFileError
from .stream import Group, Report, kinds, plans_of, read_motion, replay_arrays

KIND_NAMES = ("idle", "crawl")
GAP = 0.01  # a replayed stretch's strip ends this much (frames) before the next frame


def import_take(context: bpy.types.Context, path: str | Path, report: Report) -> str:
    """Import the take at `path` into `context.scene` (see the module); returns a line
    saying what was made. Raises `TakeFileError` (one line) for a file that is not a
    sound take, having made nothing."""
    made_before = {kind: set(getattr(bpy.data, kind)) for kind in _KINDS}
    try:
        with TakeFile(path) as take:
            return _import(context, take, report)
    except BaseException:
        for kind in _KINDS:
            collection = getattr(bpy.data, kind)
            extra = [item for item in collection if item not in made_before[kind]]
            if extra:
                bpy.data.batch_remove(extra)
        raise


_KINDS = ("objects", "meshes", "armatures", "materials", "actions", "collections")


def _import(context: bpy.types.Context, take: TakeFile, report: Report) -> str:
    frames, count = take.frames, len(take.creatures)
    report(0.0, f"{take.path.name}: {count} creatures, {frames} frames")
    ground.meshes(take.header)  # checked before anything is made
    replay = replay_arrays(take)
    kind = kinds(take, replay)
    plans = plans_of(take)
    collection = bpy.data.collections.new(take.path.stem)
    context.scene.collection.children.link(collection)
    rigs: dict[Plan, tuple[bpy.types.Armature, bpy.types.Mesh]] = {}
    offsets: dict[Plan, np.ndarray] = {}
    groups = []
    for p, (plan, members) in enumerate(plans.items()):
        stem = f"plan{p}" if len(plans) > 1 else "plan"
        armature, offsets[plan] = rig.plan_armature(f"{stem}_skeleton", plan, collection)
        rigs[plan] = (armature, rig.plan_mesh(f"{stem}_skin", plan))
        simulated = [c for c in members if (kind[:, c] < 0).any()]
        if simulated:
            groups.append(Group(plan, simulated, offsets[plan]))
    root = read_motion(take, groups, kind, replay, report)
    clips = _clip_actions(take, plans, offsets, kind)
    visible = take.per_frame("creature_visible") if take.roster else None
    made = _Made()
    own = {c: (g, i) for g in groups for i, c in enumerate(g.creatures)}
    plan_of = {c: plan for plan, members in plans.items() for c in members}
    for c, creature in enumerate(take.creatures):
        material = rig.material(f"{creature.name}_material", take.header, c)
        skeleton, skin = rig.creature_objects(creature.name, *rigs[plan_of[c]], material,
                                              collection)  # fmt: skip
        made.keys += _root_action(skeleton, creature.name, root[:, c])
        if c in own:
            made.keys += _pose_action(skeleton, creature.name, *own[c])
        if replay is not None and (kind[:, c] >= 0).any():
            made.strips += _clip_strips(take, skeleton, c, kind[:, c],
                                        replay["replay_phase"][:, c], clips)  # fmt: skip
        if visible is not None and not visible[:, c].all():
            made.keys += _visibility(skin, creature.name, visible[:, c])
        if (c + 1) % max(1, count // 20) == 0:
            report(0.5 + 0.5 * (c + 1) / count, f"creature {c + 1} of {count}")
    on_ground = ground.make(take, collection)
    _set_rate(context.scene, take.fps)
    context.scene.frame_start, context.scene.frame_end = 0, frames - 1
    report(1.0, "done")
    return (
        f"{take.path.name}: {count} creatures of {len(plans)} body"
        f" plan{'s' if len(plans) > 1 else ''}, {frames} frames at {take.fps:g} fps;"
        f" {len(own)} with keys of their own, {len(clips)} shared clip actions in"
        f" {made.strips} strips; {made.keys} keys"
        + (f"; {on_ground} ground meshes" if on_ground else "")
    )


@dataclass
class _Made:
    """What an import made so far."""

    keys: int = 0
    strips: int = 0


def _clip_actions(
    take: TakeFile, plans: dict[Plan, list[int]], offsets: dict[Plan, np.ndarray], kind: np.ndarray
) -> dict[tuple[int, int], bpy.types.Action]:
    """One cyclic action per clip and kind some creature replays: (clip, kind) -> action."""
    actions: dict[tuple[int, int], bpy.types.Action] = {}
    plan_of = {c: plan for plan, members in plans.items() for c in members}
    for i, clip in enumerate(take.clips):
        users = np.flatnonzero(take.replayed == i)
        used = sorted({int(k) for k in np.unique(kind[:, users]) if k >= 0}) if len(users) else []
        if not used:
            continue
        plan = plan_of[int(users[0])]
        if any(plan_of[int(c)] != plan for c in users):
            raise TakeFileError(f"{take.path}: header.replay.creatures: clip {i} is replayed"
                                " by creatures of different body plans")  # fmt: skip
        poses = take.static(f"replay_clip_{i}", (sum(clip.frames), clip.bodies, 7), "<f8")
        for k in used:
            start = 0 if k == 0 else clip.frames[0]
            try:
                rows = slice(start, start + clip.frames[k])
                rotation, location = clip_keys(plan, offsets[plan], poses, rows, CLIP_KEYS)
            except ValueError as error:
                raise TakeFileError(f"{take.path}: replay_clip_{i}: {error}") from None
            action, _, channels = keys.new_action(f"clip{i}_{KIND_NAMES[k]}")
            keys.bone_curves(channels, plan.names, np.arange(len(rotation), dtype=np.float64),
                             rotation, location, cyclic=True)  # fmt: skip
            actions[(i, k)] = action
    return actions


def _pose_action(skeleton: bpy.types.Object, name: str, group: Group, i: int) -> int:
    """`<name>_pose`: the creature's own bone keys at the frames it is simulated, in a
    `physical` NLA track (under the clips'). Returns the keys written."""
    keyed, rotation, location = group.keys(i)
    action, _, channels = keys.new_action(f"{name}_pose")
    written = keys.bone_curves(channels, group.plan.names, keyed.astype(np.float64),
                               continuous(rotation, axis=0), location)  # fmt: skip
    track = skeleton.animation_data.nla_tracks.new()
    track.name = "physical"
    strip = track.strips.new(action.name, int(keyed[0]), action)  # action frames = frames
    strip.use_sync_length = False  # (its one slot: Blender assigns it)
    return int(written)


def _clip_strips(
    take: TakeFile,
    skeleton: bpy.types.Object,
    c: int,
    kind: np.ndarray,
    phase: np.ndarray,
    clips: dict[tuple[int, int], bpy.types.Action],
) -> int:
    """Creature `c`'s `clips` track: a strip of the shared action per replayed stretch."""
    index = int(take.replayed[c])
    clip = take.clips[index]
    rate = (1.0 / take.fps) / clip.dt
    stretches: list[Segment] = segments(kind, phase, clip.frames, rate_or_one(rate))
    track = skeleton.animation_data.nla_tracks.new()
    track.name = "clips"
    for s, stretch in enumerate(stretches):
        action = clips[(index, stretch.kind)]
        length = stretch.end - stretch.first - GAP
        span = (stretch.phase * CLIP_KEYS, (stretch.phase + length * stretch.rate) * CLIP_KEYS)
        follows = s + 1 < len(stretches) and stretches[s + 1].first == stretch.end
        keys.strip(track, f"{action.name}.{s}", action, stretch.first, span,
                   stretch.rate * CLIP_KEYS, hold=follows)  # fmt: skip
    return len(stretches)


def _root_action(skeleton: bpy.types.Object, name: str, root: np.ndarray) -> int:
    """The armature object's action `<name>_root`: its ground frame at every frame
    (location x, y; rotation about z). Returns the keys written."""
    frames = np.arange(len(root), dtype=np.float64)
    action, slot, channels = keys.new_action(f"{name}_root")
    for i in range(2):
        keys.curve(channels, "location", i, frames, root[:, i], "root")
    keys.curve(channels, "rotation_euler", 2, frames, root[:, 2], "root")
    data = skeleton.animation_data_create()
    data.action = action
    data.action_slot = slot
    return 3 * len(frames)


def _visibility(skin: bpy.types.Object, name: str, shown: np.ndarray) -> int:
    """`<name>_shown`: the skin hidden (viewport and render) while the creature is not
    in the take (keys where it comes and goes). Returns the keys written."""
    changes = np.flatnonzero(np.diff(shown.astype(np.int8))) + 1
    at = np.concatenate([[0], changes]).astype(np.float64)
    hidden = (~shown[at.astype(int)]).astype(np.float64)
    action, slot, channels = keys.new_action(f"{name}_shown")
    for path in ("hide_viewport", "hide_render"):
        keys.curve(channels, path, 0, at, hidden, "roster", keys.CONSTANT)
    data = skin.animation_data_create()
    data.action = action
    data.action_slot = slot
    return 2 * len(at)


def _set_rate(scene: bpy.types.Scene, fps: float) -> None:
    """`scene.render.fps` / `fps_base` for `fps` (integer rates exactly)."""
    ratio = Fraction(fps).limit_denominator(1001)
    scene.render.fps = ratio.numerator
    scene.render.fps_base = ratio.denominator
