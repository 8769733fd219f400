"""Gait clips: one morphology's crawl and idle loops, recorded with the full physics,
replayed for many creatures at once without dynamics (the kinematic level of detail).

    clips = GaitClips.record(scene["creatures"][0], scene["physics"])
    clips.evaluate(kind, phase, xy, heading, out_pos, out_quat)    # K creatures at once
    qpos, qvel = clips.joint_state_at(CRAWL, phase, xy, heading)   # promotion to physics

A clip is a loop of frames (`dt` apart) stored in a *ground frame*: origin on the
ground under the creature, x axis along its travel heading, the heading's yaw removed
(roll, pitch and height kept). The crawl clip's origin moves at `speed` m/s along +x,
so a body at rest on the ground in the recording (a planted tip) stays put when the
clip is replayed along a path at that speed; the mantle surges and sways around the
origin by a few cm as it did in the recording. Each frame holds every body's pose
(mantle first, then each tentacle's links: `bodies`) and the MuJoCo joint state
(qpos: free joint then hinges; qvel) with the free joint in the ground frame, so
`joint_state_at` and `evaluate` agree: setting that qpos in the full model and running
forward kinematics gives the evaluated poses.

The loop is the stretch of the recording whose last frame best matches its first
(mantle-relative body positions; `Clip.mismatch` says by how much) and that mismatch
is spread over the loop, so the wrap moves no body farther than an ordinary frame does
(`Clip.steps`). Reads a scene creature entry;
writes only the caller's `out` arrays.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.clips.frames import nlerp, quat_power, rotate_z, to_ground, yaw_times
from ecs_tentacles.clips.gait_world import (
    GaitRecording,
    forward_poses,
    one_creature_scene,
    simulate,
)
from ecs_tentacles.numeric.optional_kernels import OptionalKernels
from ecs_tentacles.numeric.quaternions import quat_multiply
from ecs_tentacles.scene.scene_spec import PhysicsSpec

if TYPE_CHECKING:
    from ecs_tentacles.physics.posed_spheres import PosedSpheres

IDLE, CRAWL = 0, 1
# `PhysicsBackend.share`: work(start, stop) over count items, in parts on its threads
Share = Callable[[int, Callable[[int, int], None]], None]
KINDS = ("idle", "crawl")
WARMUP = 2.0  # s before recording: the creature settles, the gait is established
RECORD = 8.0  # s recorded, the loop chosen inside
LOOP = (1.0, 5.0)  # s: shortest and longest loop
GOAL_MARGIN = 2.0  # the goal is this much farther than a crawl at MAX_CRAWL_SPEED reaches
LOOP_TOLERANCE = 0.002  # m: a shorter loop this much worse than the best is preferred
MAX_CRAWL_SPEED = 1.0  # m/s: far above what creatures crawl (about 0.1 m/s)
# the kernels' reach-sphere arguments when none are wanted
_NONE, _NO_BOUNDS, _NO_CENTRES = np.zeros(0, np.int64), np.zeros(0), np.zeros((0, 3))


@dataclass
class Clip:
    """One loop of `frames` frames, ground frame (shapes (frames, ...))."""

    kind: str
    dt: float  # s per frame
    speed: float  # m/s along the ground frame's +x (0 for idle)
    pos: np.ndarray  # (F, B, 3)
    quat: np.ndarray  # (F, B, 4) wxyz
    qpos: np.ndarray  # (F, nq): free joint (ground frame) then hinges
    qvel: np.ndarray  # (F, nv): free joint linear velocity in the ground frame
    mismatch: float  # m: farthest body's distance between the loop's end and start, recorded
    span: tuple[int, int]  # (first, end) frames of the recording the loop was cut from

    @property
    def frames(self) -> int:
        return len(self.pos)

    @property
    def duration(self) -> float:
        return self.frames * self.dt

    def steps(self) -> np.ndarray:
        """(F,) the farthest body's move (m, ground frame) from each frame to the next; the
        last is the wrap (last frame -> first): no larger than the others once closed."""
        moves: np.ndarray = np.linalg.norm(np.roll(self.pos, -1, axis=0) - self.pos, axis=-1)
        farthest: np.ndarray = moves.max(axis=-1)
        return farthest


@dataclass
class GaitClips:
    """The idle and crawl clips of one morphology, stacked for vectorised replay."""

    key: tuple[object, ...]  # the physics morphology key (`model_layout(...).key`)
    bodies: list[str]
    idle: Clip
    crawl: Clip
    seconds: float  # wall-clock cost of recording both
    store_lag: float  # m: how far the Transform store lagged the recorded qpos (info)
    kept: bool = False  # read back from the clips kept on disk (`clips.disk`), not recorded

    def __post_init__(self) -> None:
        # Both clips stacked: row offset[kind] + frame holds that frame's pose (position,
        # then rotation) and its change to the next frame of its loop (the rotation's
        # sign chosen the shorter way round), so a fractional phase is one fused lerp.
        pose, change = [], []
        for clip in (self.idle, self.crawl):
            here = np.concatenate([clip.pos, clip.quat], axis=-1)
            after = np.roll(here, -1, axis=0)
            flip = np.sum(here[..., 3:] * after[..., 3:], axis=-1) < 0.0
            after[..., 3:][flip] *= -1.0
            pose.append(here)
            change.append(after - here)
        self._pose = np.concatenate(pose)
        self._change = np.concatenate(change)
        self._offset = np.array([0, self.idle.frames], dtype=np.int64)
        self._frames = np.array([self.idle.frames, self.crawl.frames], dtype=np.int64)

    @classmethod
    def record(
        cls,
        creature: dict[str, object],
        physics: PhysicsSpec | None = None,
        *,
        warmup: float = WARMUP,
        seconds: float = RECORD,
        loop: tuple[float, float] = LOOP,
    ) -> GaitClips:
        """Record `creature` (a scene creature entry) alone with the full physics.

        Crawl: a goal straight ahead, out of reach for the whole recording; idle: no
        goal. Each is stepped `warmup` s, then `seconds` s are recorded and the best
        loop of `loop` (shortest, longest) s is cut from them.
        """
        if not 0 < loop[0] < loop[1] <= seconds:
            raise ValueError(f"loop: must be 0 < shortest < longest <= seconds, got {loop}")
        goal = (warmup + seconds) * MAX_CRAWL_SPEED + GOAL_MARGIN
        crawling = simulate(one_creature_scene(creature, physics, goal), warmup, seconds)
        resting = simulate(one_creature_scene(creature, physics, None), warmup, seconds)
        return cls(
            key=crawling.key,
            bodies=crawling.bodies,
            idle=cut_loop(resting, "idle", loop),
            crawl=cut_loop(crawling, "crawl", loop),
            seconds=crawling.seconds + resting.seconds,
            store_lag=max(crawling.store_lag, resting.store_lag),
        )

    def clip(self, kind: int) -> Clip:
        """The `IDLE` or `CRAWL` clip."""
        return (self.idle, self.crawl)[kind]

    # -- replay ----------------------------------------------------------------------
    def evaluate(
        self,
        kind: np.ndarray,
        phase: np.ndarray,
        xy: np.ndarray,
        heading: np.ndarray,
        out_pos: np.ndarray,
        out_quat: np.ndarray,
        *,
        interpolate: bool = True,
        rows: np.ndarray | None = None,
        body_rows: np.ndarray | None = None,
        spheres: tuple[PosedSpheres, np.ndarray] | None = None,
        share: Share | None = None,
    ) -> None:
        """Body poses of K creatures into `out_pos` (K, B, 3) and `out_quat` (K, B, 4),
        or into their rows `rows` (K,) of larger (N, B, .) arrays (a batch's poses), or,
        given `body_rows` (N, B), body b of creature k into row `body_rows[rows[k], b]`
        of `out_pos` (M, 3) and `out_quat` (M, 4): the Transform store's rows of a
        batch's bodies (`Batch.body_rows`), consecutive or not.

        `kind` (K,) is `IDLE` or `CRAWL`; `phase` (K,) the frame in that clip (any real
        number: it wraps; fractions interpolate positions linearly and rotations by
        nlerp, or take the nearest frame without `interpolate`); `xy` (K, 2) the ground
        frame's origin and `heading` (K,) its yaw (radians).

        `spheres` (the contact proxies' `PosedSpheres` and each creature's roster index,
        (K,)): their reach spheres as well, found as the poses are written, where the
        kernels run (the numpy path leaves them unknown).

        `share(K, work)` runs `work(start, stop)` over the creatures in parts, each
        part's poses by the kernel on its own thread (`PhysicsBackend.share`): the
        same numbers, a creature's poses depend on nothing but its own inputs.
        """
        kind = np.asarray(kind, dtype=np.int64)
        phase = np.asarray(phase, dtype=np.float64)
        frames = self._frames[kind]
        fast = KERNELS.get()
        if fast is not None:
            below = np.floor(phase) if interpolate else np.rint(phase)
            row = self._offset[kind] + np.mod(below.astype(np.int64), frames)
            where = np.ascontiguousarray(xy, dtype=np.float64)
            turn = np.ascontiguousarray(heading, dtype=np.float64)
            fraction = phase - below
            into = np.arange(len(kind)) if rows is None else np.asarray(rows, dtype=np.int64)
            known, of = (None, _NONE) if spheres is None else spheres
            reach = (_NONE, _NO_BOUNDS, _NO_CENTRES, _NO_BOUNDS) if known is None else (
                known.start, known.rbound, known.centre, known.radius)  # fmt: skip
            of = np.asarray(of, dtype=np.int64)

            def part(start: int, stop: int) -> None:
                k = slice(start, stop)
                mine = (row[k], fraction[k], interpolate, where[k], turn[k], into[k])
                found = of[k] if len(of) else of
                if body_rows is None:
                    fast.place(self._pose, self._change, *mine, out_pos, out_quat, found,
                               *reach)  # fmt: skip
                else:
                    fast.place_scattered(self._pose, self._change, *mine, body_rows, out_pos,
                                         out_quat, found, *reach)  # fmt: skip

            if share is None:
                part(0, len(kind))
            else:
                share(len(kind), part)
            if known is not None:
                known.known[of] = True
            return
        if rows is not None or body_rows is not None:  # numpy: whole arrays, then a scatter
            bodies = self._pose.shape[1]
            pos, quat = np.empty((len(kind), bodies, 3)), np.empty((len(kind), bodies, 4))
            self.evaluate(kind, phase, xy, heading, pos, quat, interpolate=interpolate)
            at = np.arange(len(kind)) if rows is None else rows
            if body_rows is not None:
                at = body_rows[at]
            out_pos[at], out_quat[at] = pos, quat
            return
        if interpolate:
            below = np.floor(phase)
            row = self._offset[kind] + np.mod(below.astype(np.int64), frames)
            pose = self._pose[row]
            pose += self._change[row] * (phase - below)[:, None, None]
            quat = pose[..., 3:]
            quat /= np.sqrt(np.einsum("kbi,kbi->kb", quat, quat))[..., None]
        else:
            pose = self._pose[self._offset[kind] + np.mod(np.rint(phase).astype(np.int64), frames)]
        xy = np.asarray(xy, dtype=np.float64)
        _place(pose, xy, np.asarray(heading, dtype=np.float64), out_pos, out_quat)

    def joint_state_at(
        self, kind: int, phase: float, xy: np.ndarray, heading: float
    ) -> tuple[np.ndarray, np.ndarray]:
        """The full MuJoCo qpos and qvel of one creature shown by `evaluate` with these values.

        Free joint placed in the world (position, orientation, linear velocity); hinge
        angles and velocities as recorded (interpolated like `evaluate` for a fractional
        phase).
        """
        clip = self.clip(kind)
        below = float(np.floor(phase))
        t = float(phase) - below
        a = int(below) % clip.frames
        b = (a + 1) % clip.frames
        qpos = clip.qpos[a] + (clip.qpos[b] - clip.qpos[a]) * t
        qpos[3:7] = nlerp(clip.qpos[a, 3:7], clip.qpos[b, 3:7], np.array(t))
        qvel = clip.qvel[a] + (clip.qvel[b] - clip.qvel[a]) * t
        qpos[0:3] = rotate_z(qpos[0:3], heading)
        qpos[0:2] += np.asarray(xy, dtype=np.float64)
        qpos[3:7] = yaw_times(heading, qpos[3:7])
        qvel[0:3] = rotate_z(qvel[0:3], heading)  # angular velocity is in the body frame
        return qpos, qvel


KERNELS = OptionalKernels("ecs_tentacles.clips.kernels", "ECS_TENTACLES_REPLAY")


def _place(
    pose: np.ndarray, xy: np.ndarray, heading: np.ndarray, out_pos: np.ndarray, out_quat: np.ndarray
) -> None:
    """Ground-frame poses (K, B, 7) into the world at `xy` (K, 2) / `heading` (K,)."""
    c = np.cos(heading)[:, None]
    s = np.sin(heading)[:, None]
    x, y = pose[..., 0], pose[..., 1]
    np.multiply(c, x, out=out_pos[..., 0])
    out_pos[..., 0] -= s * y
    out_pos[..., 0] += xy[:, 0:1]
    np.multiply(s, x, out=out_pos[..., 1])
    out_pos[..., 1] += c * y
    out_pos[..., 1] += xy[:, 1:2]
    out_pos[..., 2] = pose[..., 2]
    hc = np.cos(0.5 * heading)[:, None]
    hs = np.sin(0.5 * heading)[:, None]
    w, qx, qy, qz = pose[..., 3], pose[..., 4], pose[..., 5], pose[..., 6]
    np.multiply(hc, w, out=out_quat[..., 0])
    out_quat[..., 0] -= hs * qz
    np.multiply(hc, qx, out=out_quat[..., 1])
    out_quat[..., 1] -= hs * qy
    np.multiply(hc, qy, out=out_quat[..., 2])
    out_quat[..., 2] += hs * qx
    np.multiply(hc, qz, out=out_quat[..., 3])
    out_quat[..., 3] += hs * w


def cut_loop(
    rec: GaitRecording, kind: str, loop: tuple[float, float], *, close: bool = True
) -> Clip:
    """The loop of `rec` whose end best matches its start, as a ground-frame `Clip`.

    The origin moves from the mantle's first to its last ground point at constant
    speed; the heading is the travel direction (crawl) or the mantle's first yaw
    (idle), turning with the mantle's yaw at a constant rate over the loop, so a slow
    spin or drift is taken out and the loop closes. Idle speed is 0 (a drift is
    dropped). With `close`, the joint angles' (and the
    mantle's height and tilt) mismatch at the wrap is spread linearly over the loop
    too, so the wrap shows no jump; poses are forward kinematics of the clip's qpos.
    """
    mantle = rec.pos[:, 0, :2]
    shortest, longest = round(loop[0] / rec.dt), round(loop[1] / rec.dt)
    first, end, mismatch = best_loop(rec.pos, rec.quat[:, 0], shortest, longest)
    progress = mantle[end] - mantle[first]
    yaw = np.unwrap(mantle_yaw(rec.quat[:, 0]))
    spin = yaw[end] - yaw[first]  # the mantle's turn over the loop, taken out of the clip
    if kind == "crawl":
        base = float(np.arctan2(progress[1], progress[0])) - 0.5 * spin
    else:
        base = float(yaw[first])
    n = end - first
    share = np.arange(n + 1) / n  # the loop's frames and the one it wraps to
    origin = mantle[first] + share[:, None] * progress
    heading = base + share * spin
    qpos = rec.qpos[first : end + 1].copy()
    qvel = rec.qvel[first:end].copy()
    root_pos, root_quat = to_ground(qpos[:, None, 0:3], qpos[:, None, 3:7], origin, heading)
    qpos[:, 0:3], qpos[:, 3:7] = root_pos[:, 0], root_quat[:, 0]
    if close:
        _close(qpos, share)
    qpos = qpos[:n]
    qvel[:, 0:3] = rotate_z(qvel[:, 0:3], -heading[:n])
    pos, quat = forward_poses(rec.model, rec.bodies, qpos)
    speed = float(np.linalg.norm(progress)) / (n * rec.dt) if kind == "crawl" else 0.0
    return Clip(kind, rec.dt, speed, pos, quat, qpos, qvel, mismatch, (first, end))


def _close(qpos: np.ndarray, share: np.ndarray) -> None:
    """Spread the mismatch between the last row of `qpos` (ground frame) and its first
    over the rows, in place, so the last equals the first (free joint then hinges)."""
    qpos[:, 7:] -= share[:, None] * (qpos[-1, 7:] - qpos[0, 7:])
    qpos[:, 0:3] -= share[:, None] * (qpos[-1, 0:3] - qpos[0, 0:3])
    # the rotation taking the last frame's mantle to the first's, applied by degrees
    conjugate = qpos[-1, 3:7] * np.array([1.0, -1.0, -1.0, -1.0])
    correction = quat_multiply(qpos[0, 3:7], conjugate)
    qpos[:, 3:7] = quat_multiply(quat_power(correction, share), qpos[:, 3:7])


def best_loop(
    pos: np.ndarray, mantle_quat: np.ndarray, shortest: int, longest: int
) -> tuple[int, int, float]:
    """(first, end, mismatch): frames first < end, end - first in [shortest, longest], whose
    body positions relative to the mantle (its yaw removed) differ least, by `mismatch` m
    (the farthest body's distance); `pos` (F, B, 3), `mantle_quat` (F, 4)."""
    frames = len(pos)
    if shortest >= frames - 1:
        raise ValueError(f"loop: shortest ({shortest} frames) must be < recorded frames ({frames})")
    relative = pos.copy()
    relative[..., :2] -= pos[:, :1, :2]
    relative = rotate_z(relative, -mantle_yaw(mantle_quat)[:, None])
    gaps = np.full((frames, longest - shortest + 1), np.inf)
    for first in range(frames - 1 - shortest):
        ends = np.arange(first + shortest, min(first + longest, frames - 1) + 1)
        distance = np.linalg.norm(relative[ends] - relative[first], axis=-1)
        gaps[first, : len(ends)] = distance.max(axis=-1)
    # the shortest loop among those within LOOP_TOLERANCE of the best (less to store)
    fits = gaps <= gaps.min() + LOOP_TOLERANCE
    length = int(np.argmax(fits.any(axis=0)))
    first = int(np.argmin(gaps[:, length]))
    return first, first + shortest + length, float(gaps[first, length])


def mantle_yaw(quat: np.ndarray) -> np.ndarray:
    """The heading (rad) of the x axis of rotations `quat` (..., 4) projected on the ground."""
    w, x, y, z = quat[..., 0], quat[..., 1], quat[..., 2], quat[..., 3]
    yaw: np.ndarray = np.arctan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))
    return yaw
