"""Kinematic creatures moved by gait clips: the `Replay` the level of detail asks for poses.

Per creature (roster order) it keeps a ground frame (`xy`, `heading`), a clip (`kind`:
idle or crawl) and a `phase` in frames. Each frame (`advance`) every kinematic
creature turns toward where the plugins say it is going (the `TravelTargets` entries; at
most `TURN_RATE`), moves along its heading at its morphology's crawl speed, steps its
clip one frame on, and its body poses are written once, straight into the Transform
store (which the renderer, recorders, proxies, rig and level of detail read): not into
its batch's pose rows as well, which keep its last stepped pose. The sync leaves those
rows (`Batch.show`), and whoever reads a replayed creature's poses through its batch
gets them from the store (`Batch.poses`, `Batch.all_poses`: views, snapshots). A
creature that starts
replaying (`start`) keeps where it stands and which way it faces; promoted again, it
starts the physics from the joint state of the pose it was shown in (`joint_state`).
On terrain the clips (recorded on the plane) are draped over the heightfield: each body
is raised by the ground's height under it, so the tips stay on the ground; promoted, a
creature starts from the clip's pose raised until it rests on the highest ground under
it (the relief under it is the most a body can jump then).

Everything per frame is whole-array work per morphology; the clips are recorded once
per morphology (`ClipCache`) the first time one of its creatures is kinematic.
"""

from __future__ import annotations

import logging
import math
from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.clips.cache import ClipCache
from ecs_tentacles.clips.clips import CRAWL, IDLE, GaitClips, mantle_yaw
from ecs_tentacles.ground import ground_of
from ecs_tentacles.numeric.optional_kernels import OptionalKernels
from ecs_tentacles.physics.registries import TravelTargets
from ecs_tentacles.physics.tiers import KINEMATIC

if TYPE_CHECKING:
    from ecs_tentacles.host import Host
    from ecs_tentacles.physics.batch import Batch
    from ecs_tentacles.physics.posed_spheres import PosedSpheres
    from ecs_tentacles.roster_change import RosterChange
    from ecs_tentacles.store import TransformStore

log = logging.getLogger("ecs_tentacles.clips")

KERNELS = OptionalKernels("ecs_tentacles.clips.kernels", "ECS_TENTACLES_REPLAY")
SHARED = ClipCache(disk=True)  # clips by morphology: every world of this process, kept on disk
TURN_RATE = math.radians(60.0)  # rad/s a replayed creature turns toward its way
ARRIVED = 0.05  # m: closer than this to its target, a replayed creature idles
DIRECT = True  # replayed poses into the Transform store only (False: into the batches, synced)
SPHERES = True  # reach spheres found as poses are written (False: the next frame reads them)


class ClipReplay:
    """Gait-clip replay for every kinematic creature of one world."""

    def __init__(self, world: Host, cache: ClipCache | None = None):
        self.world = world
        self.roster = roster = world.physics.roster
        self.cache = cache if cache is not None else SHARED
        count = len(roster)
        self.xy = np.zeros((count, 2))
        self.heading = np.zeros(count)
        self.phase = np.zeros(count)
        self.kind = np.full(count, IDLE, dtype=np.int64)
        self.clips: dict[int, GaitClips] = {}  # batch index -> its morphology's clips
        self._clip_shapes: dict[tuple[int, int], np.ndarray] = {}

    def roster_changed(self, change: RosterChange) -> None:
        """A creature came or went: its replay entries (a new one idles where it is)."""
        self.xy = change.follow_creatures(self.xy)
        self.heading = change.follow_creatures(self.heading)
        self.phase = change.follow_creatures(self.phase)
        self.kind = change.follow_creatures(self.kind, IDLE)

    def clips_of(self, batch: Batch) -> GaitClips:
        """The gait clips of `batch`'s morphology (recorded on first use)."""
        clips = self.clips.get(batch.index)
        if clips is None:
            entity = int(self.roster.entity[batch.members[0]])
            clips = self.cache.for_creature(self.world, entity)
            name = self.world.creature_name(entity)
            if clips.kept:
                log.info("gait clips for %s read from the clips kept on disk", name)
            else:
                log.info("gait clips for %s recorded in %.1f s", name, clips.seconds)
            self.clips[batch.index] = clips
        return clips

    # -- the Replay protocol -----------------------------------------------------------
    def start(self, indices: np.ndarray) -> None:
        """Creatures `indices` replay from where they stand, facing where they face."""
        roster = self.roster
        targets = _targets(self.world, roster.creature_row[indices])
        for batch in roster.batches:
            here = roster.batch_of[indices] == batch.index
            mine = indices[here]
            if not len(mine):
                continue
            clips = self.clips_of(batch)
            rows = roster.row_of[mine]
            kind = np.where(np.isfinite(targets[here, 0]), CRAWL, IDLE)
            xpos, xquat = batch.placed_poses(rows)  # (a row not placed yet: as shown)
            mantle_pos, mantle_quat = xpos[:, 0], xquat[:, 0]
            yaw = mantle_yaw(mantle_quat)
            shape = _mantle_frame(xpos, mantle_pos, yaw)
            phase = np.zeros(len(mine), dtype=np.int64)
            for k in (IDLE, CRAWL):
                which = np.flatnonzero(kind == k)
                if len(which):
                    phase[which] = _nearest_frame(self._shapes(batch, clips, k), shape[which])
            for k in (IDLE, CRAWL):
                clip = clips.clip(k)
                which = kind == k
                f = phase[which]
                heading = yaw[which] - mantle_yaw(clip.quat[f, 0])
                offset = clip.pos[f, 0, :2]
                c, s = np.cos(heading), np.sin(heading)
                at = mine[which]
                self.xy[at, 0] = mantle_pos[which, 0] - (c * offset[:, 0] - s * offset[:, 1])
                self.xy[at, 1] = mantle_pos[which, 1] - (s * offset[:, 0] + c * offset[:, 1])
                self.heading[at] = heading
            self.kind[mine] = kind
            self.phase[mine] = phase

    def _shapes(self, batch: Batch, clips: GaitClips, kind: int) -> np.ndarray:
        """Every frame of a clip in its mantle's frame (F, bodies, 3), computed once."""
        key = (batch.index, kind)
        shapes = self._clip_shapes.get(key)
        if shapes is None:
            clip = clips.clip(kind)
            shapes = _mantle_frame(clip.pos, clip.pos[:, 0], mantle_yaw(clip.quat[:, 0]))
            self._clip_shapes[key] = shapes
        return shapes

    def joint_state(self, index: int) -> tuple[np.ndarray, np.ndarray]:
        """qpos and qvel of the pose creature `index` is shown in."""
        batch, row = self.roster.locate(index)
        clips = self.clips[batch.index]
        qpos, qvel = clips.joint_state_at(
            int(self.kind[index]), float(self.phase[index]), self.xy[index], self.heading[index]
        )
        ground = ground_of(self.world)
        if ground.extent is not None:  # the clip's flat pose, raised onto the terrain
            shown, _ = batch.poses(row)
            lift = float(np.max(ground.height(shown[:, :2])))
            qpos = qpos.copy()
            qpos[batch.root_qpos + 2] += lift
        return qpos, qvel

    # -- per frame -----------------------------------------------------------------------
    def advance(self, world: Host, dt: float) -> None:
        """Every kinematic creature one frame on its way; its poses into its batch rows."""
        roster = self.roster
        proxies = world.physics.proxies
        proxies.forget_posed()  # those the last frame posed may have moved since
        moving = np.flatnonzero(roster.tier == KINEMATIC)
        if not len(moving):
            for batch in roster.batches:
                batch.show(world.transforms, None)
            return
        ground = ground_of(world)
        targets = _targets(world, roster.creature_row[moving])
        batch_of = roster.batch_of[moving]
        speed = np.zeros(len(roster.batches))  # each batch's crawl speed, m/s
        advance = np.zeros(len(roster.batches))  # and clip frames a frame
        for index in np.unique(batch_of).tolist():
            clips = self.clips_of(roster.batches[index])
            speed[index], advance[index] = clips.crawl.speed, dt / clips.crawl.dt
        self._steer(moving, targets, batch_of, speed, advance, dt)
        transforms = world.transforms
        # each creature's reach sphere as its poses are written (the next frame's contact
        # proxies and level of detail ask): not on terrain, which lifts the bodies after
        posed = proxies.posed_spheres() if SPHERES and ground.extent is None else None
        for batch in roster.batches:
            here = batch_of == batch.index
            mine = moving[here]
            if not len(mine):
                batch.show(transforms, None)
                continue
            clips = self.clips_of(batch)
            rows = roster.row_of[mine]
            whole = bool(np.all(self.phase[mine] == np.round(self.phase[mine])))
            spheres = None if posed is None else (posed, mine)
            self._show(batch, clips, mine, rows, transforms, interpolate=not whole,
                       spheres=spheres)  # fmt: skip
            if ground.extent is not None:  # draped over the terrain, body by body
                into = transforms.pos if batch.shown is not None else batch.xpos
                at = batch.body_rows[rows] if batch.shown is not None else rows
                pos = into[at]
                lift = ground.height(pos[..., :2].reshape(-1, 2)).reshape(pos.shape[:2])
                into[at, ..., 2] = pos[..., 2] + lift

    def _steer(self, moving: np.ndarray, targets: np.ndarray, batch_of: np.ndarray,
               speed: np.ndarray, advance: np.ndarray, dt: float) -> None:  # fmt: skip
        """Creatures `moving` (their `targets`, nan: none; their batches `batch_of`) one
        frame on: each farther than `ARRIVED` from its target turns toward it (at most
        `TURN_RATE`) and crawls along its new heading at its batch's `speed`; the others
        idle where they are; every clip's phase moves its batch's `advance` frames on.
        One kernel pass over the creatures (about 3 ms of whole-array passes at 10,000),
        or numpy's arrays."""
        fast = KERNELS.get()
        if fast is None:
            self._steer_numpy(moving, targets, batch_of, speed, advance, dt)
            return
        fast.steer(moving, np.ascontiguousarray(targets, dtype=np.float64), batch_of, speed,
                   advance, dt, TURN_RATE * dt, ARRIVED, CRAWL, IDLE, self.xy, self.heading,
                   self.phase, self.kind)  # fmt: skip

    def _steer_numpy(self, moving: np.ndarray, targets: np.ndarray, batch_of: np.ndarray,
                     speed: np.ndarray, advance: np.ndarray, dt: float) -> None:  # fmt: skip
        """`_steer` as whole-array numpy (numba is not installed)."""
        way = targets - self.xy[moving]
        distance = np.hypot(way[:, 0], way[:, 1])
        crawl = np.isfinite(distance) & (distance > ARRIVED)
        wanted = np.arctan2(way[:, 1], way[:, 0])
        turn = np.angle(np.exp(1j * (wanted - self.heading[moving])))
        limit = TURN_RATE * dt
        heading = self.heading[moving] + np.where(crawl, np.clip(turn, -limit, limit), 0.0)
        self.heading[moving] = heading
        self.kind[moving] = np.where(crawl, CRAWL, IDLE)
        step = np.where(crawl, speed[batch_of], 0.0) * dt
        self.xy[moving, 0] += step * np.cos(heading)
        self.xy[moving, 1] += step * np.sin(heading)
        self.phase[moving] += advance[batch_of]

    def _show(self, batch: Batch, clips: GaitClips, mine: np.ndarray, rows: np.ndarray,
              transforms: TransformStore, *, interpolate: bool,
              spheres: tuple[PosedSpheres, np.ndarray] | None = None) -> None:  # fmt: skip
        """Creatures `mine` (rows `rows` of `batch`) in their clip poses, written once:
        into the Transform store (which the renderer, recorders, proxies and rig read),
        not into the batch's pose rows (`Batch.show`; `Batch.poses` reads them back);
        with `spheres`, their reach spheres as well (`GaitClips.evaluate`)."""
        kind, phase = self.kind[mine], self.phase[mine]
        xy, heading = self.xy[mine], self.heading[mine]
        if not DIRECT:  # into the batch's pose rows; the sync copies them like any others
            batch.place_pending(rows)  # (their pose rows are theirs from now on)
            clips.evaluate(kind, phase, xy, heading, batch.xpos, batch.xquat,
                           interpolate=interpolate, rows=rows)  # fmt: skip
            batch.show(transforms, None)
            return
        share = self.world.physics.share  # large crowds' poses on the stepping threads
        if batch.body_span() is not None:  # a uniform crowd's batch: its store rows as rows
            pos, quat = batch.store_rows(transforms)
            clips.evaluate(kind, phase, xy, heading, pos, quat, interpolate=interpolate,
                           rows=rows, spheres=spheres, share=share)  # fmt: skip
        else:
            clips.evaluate(kind, phase, xy, heading, transforms.pos, transforms.quat,
                           interpolate=interpolate, rows=rows, body_rows=batch.body_rows,
                           spheres=spheres, share=share)  # fmt: skip
        batch.show(transforms, rows)

    # -- snapshots -------------------------------------------------------------------------
    def state(self) -> tuple[np.ndarray, ...]:
        return self.xy.copy(), self.heading.copy(), self.phase.copy(), self.kind.copy()

    def set_state(self, state: tuple[np.ndarray, ...]) -> None:
        self.xy[:], self.heading[:], self.phase[:], self.kind[:] = state
        self.world.physics.proxies.forget_posed()  # the store goes back too


def _mantle_frame(pos: np.ndarray, mantle: np.ndarray, yaw: np.ndarray) -> np.ndarray:
    """Body positions (K, B, 3) relative to their mantle (K, 3), yaw (K,) turned away."""
    rel = pos - mantle[:, None, :]
    c, s = np.cos(-yaw)[:, None], np.sin(-yaw)[:, None]
    out: np.ndarray = rel.copy()
    out[..., 0] = c * rel[..., 0] - s * rel[..., 1]
    out[..., 1] = s * rel[..., 0] + c * rel[..., 1]
    return out


def _nearest_frame(shapes: np.ndarray, shape: np.ndarray, chunk: int = 64) -> np.ndarray:
    """For each pose `shape` (K, B, 3), the clip frame of `shapes` (F, B, 3) whose farthest
    body is nearest (so a creature starts replaying from the pose most like its own).
    The kernel gives the same frames, leaving a frame at its first body too far (the
    whole crowd starts replaying on the first frame: 9,872 creatures at 10,000)."""
    best = np.zeros(len(shape), dtype=np.int64)
    fast = KERNELS.get()
    if fast is not None and np.isfinite(shape).all() and np.isfinite(shapes).all():
        fast.nearest_frames(
            np.ascontiguousarray(shapes, dtype=np.float64),
            np.ascontiguousarray(shape, dtype=np.float64),
            best,
        )
        return best
    for lo in range(0, len(shape), chunk):
        part = shape[lo : lo + chunk]
        d = np.linalg.norm(part[:, None] - shapes[None], axis=-1).max(axis=-1)
        best[lo : lo + chunk] = d.argmin(axis=1)
    return best


def _targets(world: Host, creature_rows: np.ndarray) -> np.ndarray:
    """(len(creature_rows), 2) where the plugins say each creature goes; nan: nowhere."""
    found: np.ndarray | None = None
    for targets in world.registry(TravelTargets):
        answer = targets(world)
        if answer is None:
            continue
        mine = answer[creature_rows]
        if found is None:  # the first answer: its finite targets, nan elsewhere
            found = np.where(np.isfinite(mine[:, :1]), mine, np.nan)
            continue
        fill = np.isnan(found[:, 0]) & np.isfinite(mine[:, 0])
        found[fill] = mine[fill]
    return np.full((len(creature_rows), 2), np.nan) if found is None else found
