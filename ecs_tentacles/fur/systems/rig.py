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

Fur nobody reads is not evaluated: the guides of dynamic furs are (their strands carry
state from frame to frame), every other guide's evaluation is handed to `FurData.defer`
with this frame's inputs and runs when `FurData.curves` or `frames` is next read (a
take's recorder, the renderer, an exporter, a snapshot, a script), giving the same bits
it would have given here. A headless crowd with no recorder then pays for the dynamic
guides only, and once nobody has read the fur for a second (`UNREAD_SECONDS`; the
world's start counts as a read) only the ones of creatures the level of detail does not
replay: a replayed creature's strands then rest (marked fresh, they start again from the
rig's pose when next stepped; a read in the meantime shows its dynamic guides as the rig
poses them, without the strands, and every strand steps again from the next frame); the
other strands step on their own, with the bits a step of every strand gives them
(`Rig.rest_replayed` False: every strand steps, read or not). A recorder, an exporter,
the sandbox or a script reading at least once a second sees what it always saw. Fur
read since the last frame (`FurData.reads`) is evaluated here, every guide at once, as
it will be read again.

Reads: Transform store (mantle rows), the creatures' mantle rows and the physics' tiers
(which creatures are replayed), fur ControlStore (position, rest position,
behaviour values, drives), GuideStore and FurSetStore (bind pose, re-read when
`world.resource(FurData).version` changes; when a creature spawns or is despawned only
its guides are bound or cut out, `ecs_tentacles.fur.blocks`). Writes: ControlStore
(tracked attributes), FurData's `frames` (axis, up, side, root per guide) and `curves`
(polylines), now or when first read.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.fur.bind import ControlTracks, control_plan, make_strands
from ecs_tentacles.fur.blocks import BLOCK, BindBlocks, Block
from ecs_tentacles.fur.dynamics import Strands
from ecs_tentacles.fur.rig import Bind, Plan, evaluate, use_parallel
from ecs_tentacles.fur.scratch import RigBuffers
from ecs_tentacles.fur.stores import FurData
from ecs_tentacles.fur.vectors import quat_matrices
from ecs_tentacles.numeric.keyframes import TrackSet
from ecs_tentacles.system import System

if TYPE_CHECKING:
    from ecs_tentacles.host import Host
    from ecs_tentacles.roster_change import RosterChange


STRAND_BLOCK = 4096  # dynamic guides per block (their arrays are 8x larger)
# When nobody has read the fur for UNREAD_SECONDS, the strands of replayed creatures rest
# (module doc; `Rig.rest_replayed`, per world, starts as SKIP_UNREAD_REPLAYED): a
# recorder, an exporter or a script reading at 1 Hz or more keeps every strand stepping
SKIP_UNREAD_REPLAYED = True
UNREAD_SECONDS = 1.0


class Rig(System):
    name = "rig"
    stage = "animate"
    reads = (
        "transforms.pos",
        "transforms.quat",
        "fur.controls",
        "fur.guides",
        "fur.sets",
        "creatures.mantle_row",
    )
    writes = ("fur.curves", "fur.frames", "fur.controls")
    # the dynamic blend's strand positions and velocities; when the fur was last read
    state_attributes = ("strands", "read_time")

    def __init__(self) -> None:
        self.version = -1
        self.touches = 0  # the fur's `touches` when bound: an edit since means bind anew
        # every guide's bind pose, in blocks evaluated one after the other (in cache)
        self.binds: BindBlocks | None = None
        self.tracks = ControlTracks(TrackSet([]))
        self.strands: Strands | None = None
        self.scratch = RigBuffers()  # work buffers, shared by the blocks and kept
        self.parallel = False  # numba's kernels on all cores (large furs only)
        self.track_time: float | None = None  # tracks played at this time, not the world's
        self.play_tracks = True  # False: the tool holds an edit until time moves again
        self.strand_normal = np.zeros((3, 0), dtype=np.float32)  # skin normals (3, m)
        self.strand_control = np.zeros(0, dtype=np.int64)  # the strands' controls
        self.strand_body = np.zeros(0, dtype=np.int64)  # the strands' bodies
        # the strands' guides, evaluated every frame: (their rows, their bind) in blocks
        self.eager: list[tuple[np.ndarray, Bind]] = []
        self.strand_bind: Bind | None = None  # the strands' guides' bind, in strand order
        self.reads_seen = -1  # `FurData.reads` when this rig last ran
        # False: every strand steps every frame, read or not (module doc)
        self.rest_replayed = SKIP_UNREAD_REPLAYED
        self.read_time = 0.0  # world time the fur was last read at (the start counts as read)

    @property
    def bind(self) -> Bind | None:
        """Every guide's bind pose as one `Bind` (None before the first bind)."""
        return None if self.binds is None else self.binds.whole

    def rebind(self, world: Host) -> None:
        """Re-read the bind pose, tracks and dynamic strands from the fur stores."""
        self.binds = BindBlocks.of(world.resource(FurData))
        self._bound(world)

    def _bound(self, world: Host) -> None:
        """After the blocks changed: tracks, dynamic strands and the version followed."""
        fur = world.resource(FurData)
        assert self.binds is not None
        self.tracks = ControlTracks(TrackSet(fur.tracks))
        gravity = np.asarray(world.settings.gravity, dtype=np.float64)
        self.strands = make_strands(fur, gravity, world.settings.dt)
        if self.strands is not None:  # the strands' skin normals and controls, gathered once
            guides, bind = self.strands.guides, self.binds.whole
            self.strand_normal = np.ascontiguousarray(bind.normal[:, guides], np.float32)
            self.strand_control = bind.control[guides]
            self.strand_body = bind.body[guides]
            rows = [guides[start : start + BLOCK] for start in range(0, len(guides), BLOCK)]
            self.eager = [(part, bind.part(part)) for part in rows]
            self.strand_bind = bind.part(guides)
        else:
            self.eager = []
            self.strand_bind = None
        self.parallel = use_parallel(len(self.binds))
        self.version, self.touches = fur.version, fur.touches

    def roster_changed(self, world: Host, change: RosterChange) -> None:
        """A creature came or went: its guides are bound or cut out now (the others'
        bind is kept: `BindBlocks`), every other strand keeping its state (a furred
        newcomer does not make the others' dynamic fur jump)."""
        old = self.strands
        fur = world.resource(FurData)
        binds = self.binds
        if self.version < 0 or binds is None or not len(fur.guides):
            self.version, self.binds = -1, None  # not bound (or no fur left): the next frame binds
            return
        moved = change.moved.get("fur.guides")
        if self.version == fur.version:  # no fur came or went: its bodies' rows moved
            transforms = change.moved.get("transforms")
            if transforms is not None:
                binds.removed(np.arange(len(binds)), None, transforms)
            return
        if self.touches != fur.touches:
            self.rebind(world)  # an edit not yet bound as well: bind everything
        elif change.spawned:
            if not binds.added(fur, change.added.get("fur.guides", np.zeros(0, np.int64))):
                self.rebind(world)
            else:
                self._bound(world)
        else:
            assert moved is not None
            binds.removed(moved, change.moved.get("fur.controls"), change.moved.get("transforms"))
            self._bound(world)
        self._keep_strands(old, moved)

    def _keep_strands(self, old: Strands | None, moved: np.ndarray | None) -> None:
        """Strands that were there before a roster change keep their positions and speeds."""
        new = self.strands
        if old is None or new is None or old.pos is None or old.prev is None:
            return
        now = old.guides if moved is None else moved[old.guides]  # old strands' rows now
        out = np.flatnonzero(now >= 0)
        into = np.searchsorted(new.guides, now[out])  # both sorted: guide rows ascending
        found = into < len(new.guides)
        found[found] = new.guides[into[found]] == now[out][found]
        into, out = into[found], out[found]
        if not len(into):
            return
        pos, prev, fresh = new._state()
        pos[:, :, into], prev[:, :, into] = old.pos[:, :, out], old.prev[:, :, out]
        if old.fresh is not None:
            fresh[into] = old.fresh[out]

    def process(self, world: Host, dt: float) -> None:
        fur = world.resource(FurData)
        if not len(fur.guides):
            return
        fur.discard()  # last frame's evaluation, if nobody read it, is superseded
        if self.version != fur.version or self.binds is None:
            self.rebind(world)
        binds = self.binds
        assert binds is not None
        if self.play_tracks:
            time = world.time if self.track_time is None else self.track_time
            self.tracks.apply(fur.controls, time)
        plan, dynamic = control_plan(fur)  # per-control values and skips, once a frame
        rotation = quat_matrices(world.transforms.quat[binds.bodies])
        position = world.transforms.pos[binds.bodies]
        frames, curves = fur.outputs()
        strands = self.strands
        read, self.reads_seen = fur.reads != self.reads_seen, fur.reads  # read since last frame
        if read:
            self.read_time = world.time
        unread = world.time - self.read_time > UNREAD_SECONDS
        resting = None if not unread or strands is None else self._resting_strands(world)
        if read or (strands is not None and resting is None and len(strands.guides) == len(binds)):
            self._evaluate(frames, curves, list(binds.blocks), plan, rotation, position)
            if strands is not None:  # every guide, every strand
                self._dynamics(frames, curves, rotation, dynamic)
            return
        keep = None  # the strands' guides: posed and blended now, the others when read
        if strands is not None:
            stepped = None if resting is None else np.flatnonzero(~resting)
            keep = strands.guides if stepped is None else strands.guides[stepped]
            for rows, part in self._strand_parts(stepped):
                out = np.empty((len(part), 4, 3), np.float32), np.empty_like(curves[: len(part)])
                evaluate(part, plan, rotation, position, *out, self.scratch, self.parallel)
                frames[rows], curves[rows] = out
            if len(keep):
                self._dynamics(frames, curves, rotation, dynamic, stepped)
            if resting is not None:  # they start again from the rig's pose when next stepped
                strands._state()[2][resting] = True
        blocks, parallel = list(binds.blocks), self.parallel

        def deferred() -> None:
            now_frames, now_curves = fur.outputs()
            kept = None if keep is None else (now_frames[keep], now_curves[keep])
            self._evaluate(now_frames, now_curves, blocks, plan, rotation, position, parallel)
            if kept is not None:  # the strands' blended curves stay as they are
                now_frames[keep], now_curves[keep] = kept

        fur.defer(deferred)

    def _evaluate(
        self,
        frames: np.ndarray,
        curves: np.ndarray,
        blocks: list[Block],
        plan: Plan,
        rotation: np.ndarray,
        position: np.ndarray,
        parallel: bool | None = None,
    ) -> None:
        """Every guide of `blocks` posed into `frames` and `curves`, block by block."""
        many = self.parallel if parallel is None else parallel
        for rows, part in blocks:
            evaluate(part, plan, rotation, position, frames[rows], curves[rows], self.scratch, many)

    def _resting_strands(self, world: Host) -> np.ndarray | None:
        """Which strands rest in a frame nobody reads the fur (bool, by strand): those of
        replayed creatures (`rest_replayed`); None when none does."""
        strands, binds = self.strands, self.binds
        if not self.rest_replayed or strands is None or binds is None or not len(world.creatures):
            return None
        replayed = world.physics.kinematic_creatures(len(world.creatures))
        if not replayed.any():
            return None
        mantles, bodies = world.creatures.mantle_row, binds.bodies  # the furred mantles' rows
        order = None if (np.diff(mantles) > 0).all() else np.argsort(mantles)
        if order is None:
            creature = np.searchsorted(mantles, bodies)
        else:
            creature = order[np.searchsorted(mantles[order], bodies)]
        resting = replayed[creature][self.strand_body]  # by body, then by strand
        return resting if resting.any() else None

    def _strand_parts(self, stepped: np.ndarray | None) -> Iterator[tuple[np.ndarray, Bind]]:
        """(guide rows, their bind) of the strands `stepped` (None: every strand's, bound
        once in `eager`), in blocks of `BLOCK`."""
        if stepped is None:
            yield from self.eager
            return
        strands, bound = self.strands, self.strand_bind
        assert strands is not None and bound is not None  # bound with the strands (`_bound`)
        for start in range(0, len(stepped), BLOCK):
            part = stepped[start : start + BLOCK]
            yield strands.guides[part], bound.part(part)

    def _dynamics(
        self,
        frames: np.ndarray,
        curves: np.ndarray,
        rotation: np.ndarray,
        dynamic: np.ndarray,
        cols: np.ndarray | None = None,
    ) -> None:
        """The strands `cols` (indices; None: all) stepped and blended into `curves`."""
        whole = self.strands
        assert whole is not None
        local, control, body = self.strand_normal, self.strand_control, self.strand_body
        strands = whole
        if cols is not None:  # stepped on their own, their state then put back
            strands = whole.subset(cols)
            local, control, body = np.ascontiguousarray(local[:, cols]), control[cols], body[cols]
        self._strand_step(strands, local, control, body, frames, curves, rotation, dynamic)
        if cols is not None:
            whole.put(cols, strands)

    def _strand_step(
        self,
        strands: Strands,
        local: np.ndarray,
        control: np.ndarray,
        body: np.ndarray,
        frames: np.ndarray,
        curves: np.ndarray,
        rotation: np.ndarray,
        dynamic: np.ndarray,
    ) -> None:
        turn = rotation.astype(np.float32)
        guides = strands.guides
        if len(turn) == 1:  # three row sums: a BLAS call here woke its spinning threads
            r = turn[0]
            normal = r[:, 0:1] * local[0] + r[:, 1:2] * local[1] + r[:, 2:3] * local[2]
        else:
            # C order as the one-body case's: the kernel compiled once for both (einsum
            # may hand back Fortran order, a second 6 s compile of the strand kernel)
            normal = np.einsum("mij,jm->im", turn[body], local, order="C")
        if strands.step_kernel(curves, frames, normal, dynamic[control], self.parallel):
            return
        first = int(guides[0])
        contiguous = bool(guides[-1] - first == len(guides) - 1)
        for start in range(0, len(guides), STRAND_BLOCK):  # block by block, in cache
            cols = slice(start, min(start + STRAND_BLOCK, len(guides)))
            rows = slice(first + start, first + cols.stop) if contiguous else guides[cols]
            rig = np.ascontiguousarray(curves[rows].transpose(1, 2, 0))
            root = frames[rows, 3].T
            weight = dynamic[control[cols]]
            blended = strands.step(rig, root, normal[:, cols], weight, cols)
            curves[rows] = blended.transpose(2, 0, 1)
