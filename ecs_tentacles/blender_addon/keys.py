"""Keys written in bulk: Blender actions, their F-curves and NLA strips (bpy).

Every F-curve gets all its keys at once (`keyframe_points.add(n)` and `foreach_set` of
the frames and values, interpolation and handles): never `keyframe_insert` per key,
which costs a Python call and a sort per key. Actions are Blender 4.4+'s layered ones:
one slot, one layer, one keyframe strip, its channelbag holding the curves.
"""

from __future__ import annotations

import bpy
import numpy as np

# `foreach_set` writes enum properties by their numbers (Blender's BEZT_IPO_*)
CONSTANT, LINEAR = 0, 1


def new_action(
    name: str,
) -> tuple[bpy.types.Action, bpy.types.ActionSlot, bpy.types.ActionChannelbag]:
    """A new action for objects: (action, its slot, the channelbag for the slot's curves)."""
    action = bpy.data.actions.new(name)
    slot = action.slots.new(id_type="OBJECT", name=name)
    strip = action.layers.new("keys").strips.new(type="KEYFRAME")
    return action, slot, strip.channelbag(slot, ensure=True)


def curve(
    channels: bpy.types.ActionChannelbag,
    path: str,
    index: int,
    frames: np.ndarray,
    values: np.ndarray,
    group: str = "",
    interpolation: int = LINEAR,
) -> bpy.types.FCurve:
    """An F-curve of `channels` (a channelbag) for `path[index]` with a key at each of
    `frames` of `values`; handles a third of the way to the neighbouring keys (what an
    animator who turns a key to Bezier expects)."""
    fcurve = channels.fcurves.new(path, index=index, group_name=group)
    count = len(frames)
    points = fcurve.keyframe_points
    points.add(count)
    co = np.empty((count, 2), np.float32)
    co[:, 0] = frames
    co[:, 1] = values
    points.foreach_set("co", co.ravel())
    points.foreach_set("interpolation", np.full(count, interpolation, np.int32))
    before = np.concatenate([co[:1], co[:-1]])
    after = np.concatenate([co[1:], co[-1:]])
    points.foreach_set("handle_left", (co + (before - co) / 3.0).ravel())
    points.foreach_set("handle_right", (co + (after - co) / 3.0).ravel())
    return fcurve


def bone_curves(
    channels: bpy.types.ActionChannelbag,
    names: list[str],
    frames: np.ndarray,
    rotation: np.ndarray,
    location: np.ndarray,
    cyclic: bool = False,
) -> int:
    """Curves of every bone's `rotation_quaternion` (`rotation` (F, J, 4) at `frames`)
    and the root bone's `location` ((F, 3)), grouped by bone; with `cyclic`, each curve
    repeats its keys before and after them (a clip's loop). Returns the keys written."""
    made = []
    for j, name in enumerate(names):
        path = f'pose.bones["{name}"]'
        for i in range(4):
            made.append(curve(channels, f"{path}.rotation_quaternion", i, frames,
                              rotation[:, j, i], name))  # fmt: skip
        if j == 0:
            for i in range(3):
                made.append(curve(channels, f"{path}.location", i, frames, location[:, i], name))
    if cyclic:
        for fcurve in made:
            fcurve.modifiers.new("CYCLES")
    return len(made) * len(frames)


def strip(track: bpy.types.NlaTrack, name: str, action: bpy.types.Action, first: float,
          span: tuple[float, float], rate: float, hold: bool) -> bpy.types.NlaStrip:  # fmt: skip
    """An NLA strip on `track` playing `action` frames `span` from take frame `first` at
    `rate` action frames a take frame; `hold`: it holds its last pose until the next
    strip (else nothing after its end: the track below shows)."""
    made = track.strips.new(name, int(np.floor(first)), action)
    made.use_sync_length = False
    made.action_frame_start, made.action_frame_end = span
    made.scale = 1.0 / rate
    made.frame_start = first
    made.extrapolation = "HOLD_FORWARD" if hold else "NOTHING"
    return made
