"""rig: fur guides posed from creature poses and control values (the fur/feather thesis).

Each frame: keyframed control tracks are written at `world.time` (or at `track_time`,
which the sandbox's timeline sets while it scrubs; not while `play_tracks` is off); every guide's
frame is evaluated from its bind pose and its control's effective values (lift, aim,
direction, random twist, the emotion system's drive added) as whole-array math; the
guides' rest shapes are posed in world space by the mantle's Transform; guides of
furs with the dynamic behaviour blend toward a light strand simulation from root to
tip. A world without fur returns at once. See `ecs_tentacles.fur.rig` for the math:
the guides go through `rig.evaluate` in blocks that share one scratch (no allocation
per frame), by numba kernels when numba is installed, else whole-array numpy.

Reads: Transform store (mantle rows), fur ControlStore (position, rest position,
behaviour values, drives), GuideStore and FurSetStore (bind pose, re-read when
`world.resource(FurData).version` changes). Writes: ControlStore (tracked attributes),
FurData's `frames` (axis, up, side, root per guide) and `curves` (polylines).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.fur.bind import ControlTracks, control_values, make_bind, make_strands
from ecs_tentacles.fur.dynamics import Strands
from ecs_tentacles.fur.rig import Bind, Scratch, control_table, evaluate, use_parallel
from ecs_tentacles.fur.stores import FurData
from ecs_tentacles.fur.vectors import quat_matrices
from ecs_tentacles.system import System
from ecs_tentacles.tracks import TrackSet

if TYPE_CHECKING:
    from ecs_tentacles.host import Host
    from ecs_tentacles.roster_change import RosterChange


BLOCK = 16384  # guides per block
STRAND_BLOCK = 4096  # dynamic guides per block (their arrays are 8x larger)


class Rig(System):
    name = "rig"
    stage = "animate"
    reads = ("transforms.pos", "transforms.quat", "fur.controls", "fur.guides", "fur.sets")
    writes = ("fur.curves", "fur.frames", "fur.controls")
    state_attributes = ("strands",)  # the dynamic blend's strand positions and velocities

    def __init__(self) -> None:
        self.version = -1
        self.bind: Bind | None = None
        self.bodies = np.zeros(0, dtype=np.int64)
        self.tracks = ControlTracks(TrackSet([]))
        self.strands: Strands | None = None
        # blocks of guides evaluated one after the other, so temporaries stay in cache
        self.blocks: list[tuple[slice, Bind]] = []
        self.scratch = Scratch()  # work buffers, shared by the blocks and kept
        self.parallel = False  # numba's kernels on all cores (large furs only)
        self.track_time: float | None = None  # tracks played at this time, not the world's
        self.play_tracks = True  # False: the tool holds an edit until time moves again
        self.strand_normal = np.zeros((3, 0), dtype=np.float32)  # skin normals (3, m)
        self.strand_control = np.zeros(0, dtype=np.int64)  # the strands' controls
        self.strand_body = np.zeros(0, dtype=np.int64)  # the strands' bodies

    def rebind(self, world: Host) -> None:
        """Re-read the bind pose, tracks and dynamic strands from the fur stores."""
        fur = world.resource(FurData)
        self.bind, self.bodies = make_bind(fur)
        n = len(self.bind)
        self.blocks = [
            (rows, self.bind.part(rows))
            for rows in (slice(s, min(s + BLOCK, n)) for s in range(0, n, BLOCK))
        ]
        self.tracks = ControlTracks(TrackSet(fur.tracks))
        gravity = np.asarray(world.settings.gravity, dtype=np.float64)
        self.strands = make_strands(fur, gravity, world.settings.dt)
        if self.strands is not None:  # the strands' skin normals and controls, gathered once
            guides = self.strands.guides
            self.strand_normal = np.ascontiguousarray(self.bind.normal[:, guides], np.float32)
            self.strand_control = self.bind.control[guides]
            self.strand_body = self.bind.body[guides]
        self.parallel = use_parallel(n)
        self.version = fur.version

    def roster_changed(self, world: Host, change: RosterChange) -> None:
        """A creature came or went: bind again now, every other strand keeping its state
        (a furred newcomer does not make the others' dynamic fur jump)."""
        old = self.strands
        fur = world.resource(FurData)
        if self.version < 0 or not len(fur.guides):
            return  # not bound yet: the first frame binds
        if self.version == fur.version:  # no fur came or went: its bodies' rows moved
            moved = change.moved.get("transforms")
            if moved is not None:
                self.bodies = moved[self.bodies]
            return
        self.rebind(world)
        new = self.strands
        if old is None or new is None or old.pos is None or old.prev is None:
            return
        moved = change.moved.get("fur.guides")
        now = old.guides if moved is None else moved[old.guides]  # old strands' rows now
        column = {int(row): i for i, row in enumerate(now.tolist()) if row >= 0}
        pairs = [(j, column[g]) for j, g in enumerate(new.guides.tolist()) if g in column]
        if not pairs:
            return
        into, out = (np.array(side) for side in zip(*pairs, strict=True))
        pos, prev, fresh = new._state()
        pos[:, :, into], prev[:, :, into] = old.pos[:, :, out], old.prev[:, :, out]
        if old.fresh is not None:
            fresh[into] = old.fresh[out]

    def process(self, world: Host, dt: float) -> None:
        fur = world.resource(FurData)
        if not len(fur.guides):
            return
        if self.version != fur.version:
            self.rebind(world)
        bind = self.bind
        assert bind is not None
        if self.play_tracks:
            time = world.time if self.track_time is None else self.track_time
            self.tracks.apply(fur.controls, time)
        values, dynamic = control_values(fur)
        plan = control_table(values)  # per-control values and skips, once a frame
        rotation = quat_matrices(world.transforms.quat[self.bodies])
        position = world.transforms.pos[self.bodies]
        for rows, part in self.blocks:
            evaluate(
                part,
                plan,
                rotation,
                position,
                fur.frames[rows],
                fur.curves[rows],
                self.scratch,
                self.parallel,
            )
        if self.strands is not None:
            self._dynamics(fur.frames, fur.curves, bind, rotation, dynamic)

    def _dynamics(
        self,
        frames: np.ndarray,
        curves: np.ndarray,
        bind: Bind,
        rotation: np.ndarray,
        dynamic: np.ndarray,
    ) -> None:
        strands = self.strands
        assert strands is not None
        turn = rotation.astype(np.float32)
        guides = strands.guides
        if len(turn) == 1:  # three row sums: a BLAS call here woke its spinning threads
            r, local = turn[0], self.strand_normal
            normal = r[:, 0:1] * local[0] + r[:, 1:2] * local[1] + r[:, 2:3] * local[2]
        else:
            normal = np.einsum("mij,jm->im", turn[self.strand_body], self.strand_normal)
        if strands.step_kernel(curves, frames, normal, dynamic[self.strand_control], self.parallel):
            return
        first = int(guides[0])
        contiguous = bool(guides[-1] - first == len(guides) - 1)
        for start in range(0, len(guides), STRAND_BLOCK):  # block by block, in cache
            cols = slice(start, min(start + STRAND_BLOCK, len(guides)))
            rows = slice(first + start, first + cols.stop) if contiguous else guides[cols]
            rig = np.ascontiguousarray(curves[rows].transpose(1, 2, 0))
            root = frames[rows, 3].T
            weight = dynamic[self.strand_control[cols]]
            blended = strands.step(rig, root, normal[:, cols], weight, cols)
            curves[rows] = blended.transpose(2, 0, 1)
