"""Editable keys: keep, per joint channel, only the keys a curve needs.

`reduce_rotations` is Ramer-Douglas-Peucker on rotation angle: between two kept keys
the curve is the slerp of the keys (what glTF's LINEAR rotation and USD's quaternion
interpolation do); the sample furthest from it (as an angle) is kept when it is more
than the tolerance away, until no sample is. Every round splits all joints' segments
at once (array math over frames x joints), so the rounds number the recursion depth.
`reduce_points` is the same on distance, for the root's translation.
`reduce_chunk` reduces a chunk of frames of several creatures at once (the streamed USD
writer's, `ecs_tentacles.export.usd_joint_samples`), with the curves kept and the errors.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

ROOT_TOLERANCE_M = 0.0005  # the root translation channel's tolerance with reduced keys


@dataclass(frozen=True)
class KeyReport:
    """Keys in all joint channels before and after, the largest error left (deg, m), and
    how many frames hold any key (a USD SkelAnimation samples all joints at those)."""

    before: int
    after: int
    max_rotation_error_deg: float
    max_translation_error_m: float
    sample_frames: int  # frames where any channel keeps a key (USD's time samples)
    frames: int
    creatures: int = 0  # creatures in the file (0: not counted)
    sharing: int = 0  # of them, those with replayed stretches on shared clip animations
    shared: int = 0  # the shared clip animations
    stretches: int = 0  # the replayed stretches (a skeleton each, its keys not counted)

    def line(self) -> str:
        """One line for the CLI: what was kept, and what reducing cost (when it did)."""
        if self.after == self.before:
            kept = f"{self.after} keys (every frame: nothing reduced; --keys reduced keeps fewer)"
        else:
            kept = (
                f"keys {self.before} -> {self.after} (frames with a key: {self.sample_frames} of"
                f" {self.frames}); max error {self.max_rotation_error_deg:.3f} deg,"
                f" {1000 * self.max_translation_error_m:.3f} mm"
            )
        if not self.sharing:
            return kept
        animations = "animation" if self.shared == 1 else "animations"
        return (
            f"{self.sharing} of {self.creatures} creatures replay {self.stretches} stretches on"
            f" {self.shared} shared clip {animations}; their own skeletons (physical frames):"
            f" {kept}"
        )


def slerp(a: np.ndarray, b: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Spherical interpolation of unit quaternions (..., 4) by t (...) (short way round)."""
    dot = np.einsum("...c,...c->...", a, b)
    b = np.where(dot[..., None] < 0, -b, b)
    dot = np.abs(dot)
    angle = np.arccos(np.clip(dot, -1.0, 1.0))
    small = angle < 1e-6
    sin = np.where(small, 1.0, np.sin(angle))
    wa = np.where(small, 1.0 - t, np.sin((1.0 - t) * angle) / sin)
    wb = np.where(small, t, np.sin(t * angle) / sin)
    out = wa[..., None] * a + wb[..., None] * b
    unit: np.ndarray = out / np.linalg.norm(out, axis=-1, keepdims=True)
    return unit


def angle_between(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Rotation angle (degrees) between unit quaternions (..., 4)."""
    dot = np.abs(np.einsum("...c,...c->...", a, b))
    degrees: np.ndarray = np.degrees(2.0 * np.arccos(np.clip(dot, -1.0, 1.0)))
    return degrees


def _brackets(keep: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For every (frame, channel): the last kept frame at or before it, the first at or after."""
    frames = np.arange(len(keep))[:, None]
    before = np.maximum.accumulate(np.where(keep, frames, 0), axis=0)
    after = np.minimum.accumulate(np.where(keep, frames, len(keep) - 1)[::-1], axis=0)[::-1]
    return before, after


def interpolate_rotations(q: np.ndarray, keep: np.ndarray) -> np.ndarray:
    """The curve (F, J, 4) that slerps between the kept keys of `q` (F, J, 4)."""
    before, after = _brackets(keep)
    frames = np.arange(len(q))[:, None]
    span = np.maximum(after - before, 1)
    t = np.clip((frames - before) / span, 0.0, 1.0)
    joints = np.arange(q.shape[1])[None, :]
    return slerp(q[before, joints], q[after, joints], t)


def interpolate_points(p: np.ndarray, keep: np.ndarray) -> np.ndarray:
    """The polyline (F, 3) through the kept samples of `p` (F, 3)."""
    frames = np.flatnonzero(keep)
    times = np.arange(len(p))
    return np.stack([np.interp(times, frames, p[frames, i]) for i in range(p.shape[1])], axis=1)


def _rdp(
    error_of: Callable[[np.ndarray], np.ndarray],
    shape: tuple[int, int],
    tolerance: float,
    initial: np.ndarray | None = None,
) -> np.ndarray:
    """Keep mask (F, C): endpoints (and `initial`), then each segment's worst sample while
    above tolerance."""
    keep = np.zeros(shape, bool) if initial is None else initial.copy()
    keep[0] = keep[-1] = True
    while True:
        error = error_of(keep)
        error[keep] = 0.0
        if error.max(initial=0.0) <= tolerance:
            return keep
        # segments are runs of frames after each kept key, per channel (columns)
        segment = np.cumsum(keep, axis=0) + np.arange(shape[1])[None, :] * (shape[0] + 1)
        flat_segment, flat_error = segment.T.reshape(-1), error.T.reshape(-1)
        order = np.lexsort((-flat_error, flat_segment))
        first = order[np.r_[True, flat_segment[order][1:] != flat_segment[order][:-1]]]
        worst = first[flat_error[first] > tolerance]
        channel, frame = np.divmod(worst, shape[0])
        keep[frame, channel] = True


def reduce_rotations(
    q: np.ndarray, tolerance_deg: float, needed: np.ndarray | None = None
) -> np.ndarray:
    """Keep mask (F, J): the keys each joint's rotation curve needs to stay within tolerance.
    With `needed` (F, J) only those frames count (the curve is what is shown there): the
    first and last frame of each run of them are kept, no other frame."""
    q = np.asarray(q, dtype=np.float64)
    if needed is None:
        return _rdp(
            lambda keep: angle_between(interpolate_rotations(q, keep), q),
            q.shape[:2],
            tolerance_deg,
        )
    ends = needed.copy()
    ends[1:-1] &= ~(needed[:-2] & needed[2:])

    def error(keep: np.ndarray) -> np.ndarray:  # the frames not needed bound no segment
        return np.where(needed, angle_between(interpolate_rotations(q, keep | ~needed), q), 0.0)

    keep: np.ndarray = _rdp(error, q.shape[:2], tolerance_deg, ends) & needed
    return keep


def reduce_points(p: np.ndarray, tolerance: float) -> np.ndarray:
    """Keep mask (F,): the samples a translation curve needs to stay within `tolerance` metres."""
    p = np.asarray(p, dtype=np.float64)

    def error(keep: np.ndarray) -> np.ndarray:
        errors: np.ndarray = np.linalg.norm(interpolate_points(p, keep[:, 0]) - p, axis=1)[:, None]
        return errors

    return _rdp(error, (len(p), 1), tolerance)[:, 0]


@dataclass(frozen=True)
class ReducedChunk:
    """A chunk of frames of several creatures reduced: the keys kept, the curves they give
    (what a reader interpolates between them) and the largest errors left."""

    rotation_keys: np.ndarray  # (n, C, J)
    root_keys: np.ndarray  # (n, C)
    rotations: np.ndarray  # (n, C, J, 4) the kept rotation curves
    roots: np.ndarray  # (n, C, 3) the kept root paths
    rotation_error_deg: float  # over the frames needed
    root_error_m: float


def reduce_chunk(
    local: np.ndarray, root: np.ndarray, needed: np.ndarray, tolerance_deg: float
) -> ReducedChunk:
    """The keys of joint rotations `local` (n, C, J, 4) within `tolerance_deg` among the
    frames each creature needs (`needed`, (n, C): the ends of each run of them kept), and
    of root translations `root` (n, C, 3) within `ROOT_TOLERANCE_M`; every frame is a key
    when n < 3."""
    n, count, joints = local.shape[:3]
    flat = local.reshape(n, count * joints, 4)
    wanted = np.repeat(needed, joints, axis=1)
    if n < 3:
        keep = wanted.copy()
        root_keep = np.ones((n, count), bool)
    else:
        keep = reduce_rotations(flat, tolerance_deg, wanted)
        root_keep = np.stack(
            [reduce_points(root[:, c], ROOT_TOLERANCE_M) for c in range(count)], axis=1
        )
    curve = interpolate_rotations(flat, keep | ~wanted).reshape(local.shape)
    apart = angle_between(curve.reshape(flat.shape), flat)
    paths = np.stack(
        [interpolate_points(root[:, c], root_keep[:, c]) for c in range(count)], axis=1
    )
    return ReducedChunk(
        rotation_keys=keep.reshape(n, count, joints),
        root_keys=root_keep,
        rotations=curve,
        roots=paths,
        rotation_error_deg=float(apart[wanted].max(initial=0.0)),
        root_error_m=float(np.linalg.norm(paths - root, axis=-1).max(initial=0.0)),
    )
