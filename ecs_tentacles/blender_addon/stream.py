"""A take's frames turned into what the import keys, a block of frames at a time (numpy
only: no bpy).

    replay = replay_arrays(take)              # per-frame replay arrays, whole (or None)
    groups = [Group(plan, creatures, offset)] # creatures of a plan simulated at some frame
    root = read_motion(take, groups, kind, replay, report)

`read_motion` reads the body poses block by block (`TakeFile.blocks`): every creature's
ground frame at every frame (its armature object's keys: the replay's where it is
replayed, its mantle's where it is simulated), and each group's bone keys at every frame
(`motion.bases`; only the frames where a creature is simulated are keyed). A zero-length
quaternion where a creature is simulated is an error; replayed creatures' bodies hold
zeros (the take says so), read as the identity.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .motion import Plan, bases, in_frame, root_frame
from .reader import TakeFile, TakeFileError

Report = Callable[[float, str], None]


@dataclass
class Group:
    """The creatures of one body plan that are simulated at some frame: their keys."""

    plan: Plan
    creatures: list[int]
    offset: np.ndarray
    rotation: np.ndarray = field(init=False)  # (frames, n, J, 4) float32
    location: np.ndarray = field(init=False)  # (frames, n, 3) float32


def plans_of(take: TakeFile) -> dict[Plan, list[int]]:
    """The take's body plans, each with its creatures (indices), in the take's order."""
    plans: dict[Plan, list[int]] = {}
    for c, creature in enumerate(take.creatures):
        plan = Plan.of(take.header["bodies"], creature.bodies, creature.links)
        plans.setdefault(plan, []).append(c)
    return plans


def kinds(take: TakeFile, replay: dict[str, np.ndarray] | None) -> np.ndarray:
    """(frames, creatures) int8: what each creature is at each frame (-1: simulated, its
    bodies' poses in the take; 0 or 1: replaying its clip's idle or crawl loop)."""
    if replay is None:
        return np.full((take.frames, len(take.creatures)), -1, np.int8)
    return replay["replay_kind"]


def replay_arrays(take: TakeFile) -> dict[str, np.ndarray] | None:
    """The per-frame replay arrays (kind, phase, ground frame), whole (a few numbers a
    creature-frame), or None for a take without them."""
    if take.header.get("replay") is None:
        return None
    names = ("replay_kind", "replay_phase", "replay_xy", "replay_heading")
    parts: dict[str, list[np.ndarray]] = {n: [] for n in names}
    for _, block in take.blocks(names):
        for n in names:
            parts[n].append(block[n])
    out = {n: np.concatenate(parts[n]) for n in names}
    kind = out["replay_kind"]
    bad = (kind < -1) | (kind > 1) | ((kind >= 0) & (take.replayed[None, :] < 0))
    if bad.any():
        f, c = np.argwhere(bad)[0].tolist()
        raise TakeFileError(
            f"{take.path}: replay_kind: {kind[f, c]} at frame {f}, creature {c}: must be -1,"
            " or 0 or 1 for a creature with a clip"
        )
    return out


def read_motion(
    take: TakeFile,
    groups: list[Group],
    kind: np.ndarray,
    replay: dict[str, np.ndarray] | None,
    report: Report,
) -> np.ndarray:
    """Every creature's ground frame (frames, creatures, 3: x, y, heading unwrapped), and
    each group's bone keys at every frame (filled in place; only its creatures' simulated
    frames are keys: `kind` < 0)."""
    frames = take.frames
    root = np.zeros((frames, len(take.creatures), 3))
    if replay is not None:
        root[..., :2] = replay["replay_xy"]
        root[..., 2] = replay["replay_heading"]
    for group in groups:
        n, joints = len(group.creatures), group.plan.joints
        group.rotation = np.zeros((frames, n, joints, 4), np.float32)
        group.location = np.zeros((frames, n, 3), np.float32)
    bodies = [np.stack([take.creatures[c].bodies for c in g.creatures]) for g in groups]
    for first, block in take.blocks(("pos", "quat")):
        count = len(block["pos"])
        for group, index in zip(groups, bodies, strict=True):
            physical = kind[first : first + count, group.creatures] < 0  # (count, n)
            quat = _unit(block["quat"][:, index], physical, take.path, first, index)
            pos = block["pos"][:, index[:, 0]].astype(np.float64)
            frame = root_frame(pos, quat[..., 0, :])
            mantle_pos, quat = in_frame(pos, quat, frame)
            rotation, location = bases(group.plan, group.offset, quat, mantle_pos)
            rows = slice(first, first + count)
            group.rotation[rows] = rotation
            group.location[rows] = location
            cols = np.asarray(group.creatures)
            view = root[rows][:, cols]
            view[physical] = frame[physical]
            root[rows, cols] = view
        report(0.5 * (first + count) / frames, f"frame {first + count} of {frames}")
    root[..., 2] = np.unwrap(root[..., 2], axis=0)
    return root


def _unit(
    quat: np.ndarray, physical: np.ndarray, path: Path, first: int, index: np.ndarray
) -> np.ndarray:
    """Body quaternions (count, n, J, 4) as float64 unit ones; a zero-length one at a
    physical frame is an error (replayed creatures' bodies hold zeros: the identity)."""
    quat = quat.astype(np.float64)
    length = np.linalg.norm(quat, axis=-1)
    short = length < 1e-6
    wrong = short & physical[..., None]
    if wrong.any():
        f, c, j = np.argwhere(wrong)[0].tolist()
        raise TakeFileError(
            f"{path}: quat: zero-length quaternion at frame {first + f}, body {index[c, j]}"
        )
    quat[short] = (1.0, 0.0, 0.0, 0.0)
    length[short] = 1.0
    return quat / length[..., None]
