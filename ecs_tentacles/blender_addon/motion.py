"""Body poses turned into what Blender animates: numpy only (no bpy).

An armature per creature whose bones are its bodies: the mantle's bone is the root, each
link's bone sits at the link's joint (its base, where MuJoCo's hinges are) and is the
child of the link before it (the first link: of the mantle). Armature data is shared by
the creatures of one body plan (`Plan`), so a bone's rest pose is the construction pose:
the mantle at the armature's origin, tentacle k straight out along 360 deg * k / N about
+z from the edge of the mantle's base.

What moves:
* the armature object: the creature's ground frame (x, y, heading about +z). Replayed
  frames: the take's `replay_xy` / `replay_heading`; physical frames: the mantle's x, y
  and the heading of its +x axis (`root_frame`);
* the bones: their pose relative to the rest pose in bone space (Blender's
  `location` / `rotation_quaternion`, `bases`): the mantle bone its pose in the ground
  frame, every other bone its rotation relative to its parent (links keep their joint
  offsets: hinges do not stretch).

A clip (`header.replay`) is poses in the ground frame already, so one set of bone keys
per clip and kind serves every creature replaying it (`clip_keys`); `segments` splits a
creature's replayed frames into stretches of one clip played at a steady rate.

Quaternions are (w, x, y, z), as in the take and in Blender.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from .shared import module

# Hamilton products a * b of (..., 4) quaternions: the engine's own formula
multiply: Callable[[np.ndarray, np.ndarray], np.ndarray] = module("numeric_hamilton").multiply

EPSILON = 1e-6  # clip frames: two phase steps that differ by less are the same rate
# a shared clip action's keys per clip frame (`clip_keys`): action frame = phase * this
CLIP_KEYS = 4
# an NLA strip's scale (take frames per action frame: 1 / (rate * CLIP_KEYS)) is 0.0001
# to 1000 in Blender
MIN_RATE, MAX_RATE = 0.001 / CLIP_KEYS, 10000.0 / CLIP_KEYS


def conjugate(q: np.ndarray) -> np.ndarray:
    """The inverse of unit quaternions (..., 4)."""
    inverse: np.ndarray = q * np.array([1.0, -1.0, -1.0, -1.0])
    return inverse


def rotate(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Vectors (..., 3) rotated by unit quaternions (..., 4)."""
    w = q[..., :1]
    u = q[..., 1:]
    t = 2.0 * np.cross(u, v)
    return v + w * t + np.cross(u, t)


def about_z(angle: np.ndarray | float) -> np.ndarray:
    """Quaternions (..., 4) of rotations by `angle` about +z."""
    half = 0.5 * np.asarray(angle, dtype=np.float64)
    zero = np.zeros_like(half)
    return np.stack([np.cos(half), zero, zero, np.sin(half)], axis=-1)


def continuous(q: np.ndarray, axis: int = 0) -> np.ndarray:
    """`q` with signs flipped along `axis` so neighbours never point apart (q and -q are
    one rotation; keys interpolated between opposite signs turn the long way round)."""
    q = np.moveaxis(np.asarray(q), axis, 0)
    if len(q) < 2:
        return np.moveaxis(q, 0, axis)
    flips = np.einsum("f...c,f...c->f...", q[1:], q[:-1]) < 0
    sign = np.ones(q.shape[:-1])
    sign[1:] = np.where(np.cumsum(flips, axis=0) % 2 == 1, -1.0, 1.0)
    return np.moveaxis(q * sign[..., None], 0, axis)


@dataclass(frozen=True)
class Plan:
    """A body plan: the mantle's radius and height, each tentacle's link lengths and
    radii; the joints (mantle, then links tentacle by tentacle) with their parents, rest
    rotation relative to the parent (`rest`) and in the armature (`world`), rest heads."""

    mantle_radius: float
    mantle_height: float
    tentacles: tuple[tuple[tuple[float, ...], tuple[float, ...]], ...]
    names: list[str] = field(init=False, compare=False)
    parents: np.ndarray = field(init=False, compare=False)
    rest: np.ndarray = field(init=False, compare=False)
    world: np.ndarray = field(init=False, compare=False)
    heads: np.ndarray = field(init=False, compare=False)
    tails: np.ndarray = field(init=False, compare=False)

    def __post_init__(self) -> None:
        count = len(self.tentacles)
        names, parents = ["mantle"], [-1]
        rest, world = [np.array([1.0, 0.0, 0.0, 0.0])], [np.array([1.0, 0.0, 0.0, 0.0])]
        heads = [np.zeros(3)]
        tails = [np.array([0.0, 0.0, 0.5 * self.mantle_height])]
        for k, (lengths, _) in enumerate(self.tentacles):
            angle = 2.0 * np.pi * k / count
            axis = np.array([np.cos(angle), np.sin(angle), 0.0])
            base = np.array([self.mantle_radius * axis[0], self.mantle_radius * axis[1],
                             -0.5 * self.mantle_height])  # fmt: skip
            along = 0.0
            for i, length in enumerate(lengths):
                names.append(f"t{k}_link{i}")
                parents.append(0 if i == 0 else len(names) - 2)
                rest.append(about_z(angle) if i == 0 else np.array([1.0, 0.0, 0.0, 0.0]))
                world.append(about_z(angle))
                heads.append(base + along * axis)
                along += length
                tails.append(base + along * axis)
        object.__setattr__(self, "names", names)
        object.__setattr__(self, "parents", np.array(parents))
        object.__setattr__(self, "rest", np.array(rest))
        object.__setattr__(self, "world", np.array(world))
        object.__setattr__(self, "heads", np.array(heads))
        object.__setattr__(self, "tails", np.array(tails))

    @classmethod
    def of(
        cls, bodies: list[dict[str, object]], indices: np.ndarray, links: tuple[int, ...]
    ) -> Plan:
        """The plan of a creature whose bodies (mantle first, then links tentacle by
        tentacle) are `bodies[indices]`, `links` per tentacle."""
        mantle = bodies[int(indices[0])]
        tentacles, first = [], 1
        for count in links:
            chain = [bodies[int(i)] for i in indices[first : first + count]]
            tentacles.append((tuple(float(b["length"]) for b in chain),  # type: ignore[arg-type]
                              tuple(float(b["radius"]) for b in chain)))  # type: ignore[arg-type]  # fmt: skip
            first += count
        return cls(float(mantle["radius"]), float(mantle["length"]), tuple(tentacles))  # type: ignore[arg-type]

    @property
    def joints(self) -> int:
        """Bones: the mantle and every link."""
        return len(self.names)


def root_frame(mantle_pos: np.ndarray, mantle_quat: np.ndarray) -> np.ndarray:
    """(..., 3) ground frames (x, y, heading) of physical mantles: the mantle's x and y,
    the heading of its +x axis seen from above."""
    ahead = rotate(mantle_quat, np.array([1.0, 0.0, 0.0]))
    return np.concatenate(
        [mantle_pos[..., :2], np.arctan2(ahead[..., 1], ahead[..., 0])[..., None]], axis=-1
    )


def in_frame(
    mantle_pos: np.ndarray, quat: np.ndarray, frame: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """A creature's mantle position (..., 3) and body rotations (..., J, 4) in its ground
    frame (..., 3: x, y, heading) rather than the world's."""
    turn = about_z(-frame[..., 2])
    moved = mantle_pos - np.concatenate([frame[..., :2], np.zeros_like(frame[..., :1])], axis=-1)
    return rotate(turn, moved), multiply(turn[..., None, :], quat)


def bases(
    plan: Plan, offset: np.ndarray, quat: np.ndarray, mantle_pos: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Bone keys from body poses in the armature's frame: rotations (..., J, 4) and the
    mantle bone's location (..., 3), relative to the rest pose in bone space.

    `offset` (J, 4): each bone's rest rotation in the armature relative to its joint's
    (`rest_offsets`, from the bones Blender made); `quat` (..., J, 4) unit body rotations
    in the armature's frame (joint order), `mantle_pos` (..., 3) the mantle's centre."""
    parents = plan.parents
    local = quat.copy()
    child = np.flatnonzero(parents >= 0)
    local[..., child, :] = multiply(
        conjugate(plan.rest[child]),
        multiply(conjugate(quat[..., parents[child], :]), quat[..., child, :]),
    )
    rotation = multiply(conjugate(offset), multiply(local, offset))
    location = rotate(conjugate(offset[0]), mantle_pos - plan.heads[0])
    return rotation, location


def rest_offsets(plan: Plan, bone_rotations: np.ndarray) -> np.ndarray:
    """(J, 4): each bone's rest rotation in the armature (`bone_rotations`, as Blender
    made the bones) relative to its joint's rest rotation (`plan.world`)."""
    return multiply(conjugate(plan.world), bone_rotations)


def unit(quat: np.ndarray, where: str) -> np.ndarray:
    """`quat` (..., 4) as float64 unit quaternions; a zero-length one is an error (one line)."""
    quat = np.asarray(quat, dtype=np.float64)
    length = np.linalg.norm(quat, axis=-1, keepdims=True)
    if (length < 1e-6).any():
        at = np.argwhere(length[..., 0] < 1e-6)[0].tolist()
        raise ValueError(f"{where}: zero-length quaternion at {tuple(at)}")
    unit: np.ndarray = quat / length
    return unit


@dataclass(frozen=True)
class Segment:
    """Take frames [first, end) showing clip kind `kind` from clip frame `phase`
    (in [0, frames of the kind)), `rate` clip frames a take frame."""

    first: int
    end: int
    kind: int
    phase: float
    rate: float


def segments(
    kind: np.ndarray, phase: np.ndarray, frames: tuple[int, int], rate: float
) -> list[Segment]:
    """One creature's replayed stretches from its per-frame `replay_kind` (-1: physical)
    and `replay_phase`: runs of one kind whose phase steps by one rate (modulo the kind's
    `frames`). A lone frame plays at `rate` (any rate shows its pose at the frame)."""
    out: list[Segment] = []
    kind = np.asarray(kind)
    replayed = kind >= 0
    if not replayed.any():
        return out
    period = np.asarray(frames, dtype=np.float64)[np.maximum(kind, 0)]
    step = np.diff(phase)
    step = step - period[:-1] * np.floor(step / period[:-1] + 0.5 - EPSILON)  # (-F/2, F/2]
    starts = np.zeros(len(kind), bool)
    starts[0] = True
    starts[1:] = kind[1:] != kind[:-1]
    changed = np.abs(np.diff(step)) > EPSILON * np.maximum(1.0, np.abs(step[1:]))
    starts[2:] |= changed & (kind[2:] == kind[1:-1]) & (kind[1:-1] == kind[:-2])
    bounds = np.append(np.flatnonzero(starts), len(kind))
    for first, end in zip(bounds[:-1].tolist(), bounds[1:].tolist(), strict=True):
        k = int(kind[first])
        if k < 0:
            continue
        own = float(step[first]) if end - first > 1 else rate
        if not MIN_RATE <= own <= MAX_RATE:  # a stretch Blender cannot time: frame by frame
            out += [Segment(f, f + 1, k, float(phase[f]) % frames[k], rate_or_one(rate))
                    for f in range(first, end)]  # fmt: skip
            continue
        out.append(Segment(first, end, k, float(phase[first]) % frames[k], own))
    return out


def rate_or_one(rate: float) -> float:
    """`rate` if an NLA strip can play it, else 1 (a one-frame strip shows its pose at
    its frame whatever the rate)."""
    return rate if MIN_RATE <= rate <= MAX_RATE else 1.0


def clip_poses(clip: np.ndarray, rows: slice, keys: int) -> np.ndarray:
    """One clip kind's poses (F * keys + 1, J, 7) at every 1/`keys` of a clip frame round
    its loop (the last is the first again), interpolated as a take interpolates a
    replayed creature's bodies between clip frames: positions linearly, rotations
    normalised-linearly (the next one's sign turned to the first's side)."""
    poses = clip[rows]
    count = len(poses)
    at = np.arange(count * keys + 1) / keys
    row = np.floor(at).astype(np.int64)
    t = (at - row)[:, None, None]
    first, then = poses[row % count], poses[(row + 1) % count]
    quat = unit(first[..., 3:], "replay_clip")
    after = unit(then[..., 3:], "replay_clip")
    after = np.where(np.einsum("...i,...i->...", quat, after)[..., None] < 0, -after, after)
    moved = (1 - t) * first[..., :3] + t * then[..., :3]
    turned = unit((1 - t) * quat + t * after, "replay_clip")
    return np.concatenate([moved, turned], axis=-1)


def clip_keys(
    plan: Plan, offset: np.ndarray, clip: np.ndarray, rows: slice, keys: int
) -> tuple[np.ndarray, np.ndarray]:
    """Bone keys of one clip kind (`clip[rows]`: F, J, 7 of x y z, w x y z in the ground
    frame): `keys` a clip frame round the loop (`clip_poses`), as (F * keys + 1, J, 4)
    rotations and (F * keys + 1, 3) mantle locations, signs continuous along the loop.

    Blender interpolates a bone's rotation relative to its parent, the take a body's in
    the world; keys between the clip's frames keep the two within a fraction of the
    clip's motion from one of its frames to the next (the error falls with the square
    of `keys`)."""
    poses = clip_poses(clip, rows, keys)
    rotation, location = bases(plan, offset, poses[..., 3:], poses[:, 0, :3])
    return continuous(rotation, axis=0), location
