"""A take's frames turned into what the import keys, a block of frames at a time (numpy
only: no bpy).

    replay = replay_arrays(take)              # per-frame replay arrays, whole (or None)
    groups = [Group(plan, creatures, offset)] # creatures of a plan simulated at some frame
    root = read_motion(take, groups, kind, replay, report)

`read_motion` reads the body poses block by block (`TakeFile.blocks`): every creature's
ground frame at every frame (its armature object's keys: the replay's where it is
replayed, its mantle's where it is simulated), and each group's bone keys at the frames
where a creature is simulated (`motion.bases`; replayed creatures' bodies hold zeros
there, and are not read). A zero-length quaternion where a creature is simulated is an
error.
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
    """The creatures of one body plan that are simulated at some frame, and the bone keys
    of those frames (`read_motion` fills them in): one row per simulated creature-frame,
    creature by creature, frames in order (`keys` gives a creature's)."""

    plan: Plan
    creatures: list[int]
    offset: np.ndarray
    rows: np.ndarray = field(init=False)  # (frames, n): a key row, or -1 where replayed
    rotation: np.ndarray = field(init=False)  # (rows, J, 4) float32
    location: np.ndarray = field(init=False)  # (rows, 3) float32

    def allocate(self, kind: np.ndarray) -> None:
        """Rows for the simulated frames (`kind` < 0) of `kind` (frames, creatures)."""
        simulated = (kind[:, self.creatures] < 0).T  # (n, frames), creature by creature
        rows = np.cumsum(simulated.ravel()).reshape(simulated.shape) - 1
        self.rows = np.where(simulated, rows, -1).T
        count = int(simulated.sum())
        self.rotation = np.zeros((count, self.plan.joints, 4), np.float32)
        self.location = np.zeros((count, 3), np.float32)

    def keys(self, i: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The `i`-th creature's simulated frames (K,) and their bone keys: rotations
        (K, J, 4), the mantle's location (K, 3)."""
        frames = np.flatnonzero(self.rows[:, i] >= 0)
        rows = self.rows[frames, i]
        return frames, self.rotation[rows], self.location[rows]


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
    each group's bone keys at its creatures' simulated frames (`kind` < 0; in place)."""
    frames = take.frames
    root = np.zeros((frames, len(take.creatures), 3))
    if replay is not None:
        root[..., :2] = replay["replay_xy"]
        root[..., 2] = replay["replay_heading"]
    for group in groups:
        group.allocate(kind)
    bodies = [np.stack([take.creatures[c].bodies for c in g.creatures]) for g in groups]
    for first, block in take.blocks(("pos", "quat")):
        count = len(block["pos"])
        for group, index in zip(groups, bodies, strict=True):
            at, i = np.nonzero(group.rows[first : first + count] >= 0)  # simulated here
            if not len(at):
                continue
            quat = _unit(block["quat"][at[:, None], index[i]], take.path, first + at, index[i])
            pos = block["pos"][at, index[i, 0]].astype(np.float64)
            frame = root_frame(pos, quat[:, 0])
            mantle_pos, quat = in_frame(pos, quat, frame)
            rotation, location = bases(group.plan, group.offset, quat, mantle_pos)
            rows = group.rows[first + at, i]
            group.rotation[rows] = rotation
            group.location[rows] = location
            root[first + at, np.asarray(group.creatures)[i]] = frame
        report(0.5 * (first + count) / frames, f"frame {first + count} of {frames}")
    root[..., 2] = np.unwrap(root[..., 2], axis=0)
    return root


def _unit(quat: np.ndarray, path: Path, frames: np.ndarray, bodies: np.ndarray) -> np.ndarray:
    """Simulated bodies' quaternions (K, J, 4) as float64 unit ones; one of zero length
    is an error naming its frame (`frames` (K,)) and body (`bodies` (K, J))."""
    quat = quat.astype(np.float64)
    length = np.linalg.norm(quat, axis=-1)
    short = length < 1e-6
    if short.any():
        k, j = np.argwhere(short)[0].tolist()
        raise TakeFileError(
            f"{path}: quat: zero-length quaternion at frame {frames[k]}, body {bodies[k, j]}"
        )
    unit: np.ndarray = quat / length[..., None]
    return unit
