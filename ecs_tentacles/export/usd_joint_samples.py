"""The time samples of a skinned USD's creatures, chunk of frames by chunk.

    samples = PlanSamples(pxr, layer, plan, keys, frames, timeline)   # one body plan's
    for first, chunk in source.chunks():
        origin, yaw = samples.add(first, chunk)      # root motion as written

Per creature and frame: the root's motion on its SkelRoot (translate, float3: the
mantle's position; and for a creature with replayed stretches a rotateZ, its heading:
the ground frame's where a stretch shows, the mantle's own on its physical frames,
unwrapped), and the joints' rotations on its own SkelAnimation (one quatf array, the
root's being the mantle's rotation seen from that heading) at the frames its own
skeleton needs (`Timeline.samples` of `ecs_tentacles.export.usd_clips`: every frame for
a creature that never replays). Rotations come from `ecs_tentacles.skin.streamed` for
every creature of a plan at once. With `Keys("reduced")` each chunk is reduced on its own
with the last frame of the chunk before as its first (a key already written: every
chunk's ends are kept), so the error stays within the tolerance at every frame, the
seams included; the frames kept are those where any joint of a creature has a key (a
SkelAnimation samples all its joints at once), among the frames its own skeleton needs
(the ends of each run of them kept). `ChunkTally` adds up the key report.

Reads chunks of a take; writes time samples through a `StreamedLayer`.
"""

from __future__ import annotations

from types import ModuleType

import numpy as np

from ecs_tentacles.export.names import part
from ecs_tentacles.export.usd_clips import Timeline
from ecs_tentacles.export.usd_layer import StreamedLayer
from ecs_tentacles.export.usd_plans import BodyPlan
from ecs_tentacles.skin.keys import KeyReport, reduce_chunk
from ecs_tentacles.skin.rig import Keys
from ecs_tentacles.skin.streamed import JointRotations
from ecs_tentacles.take import Take


class PlanSamples:
    """The time samples of one body plan's creatures: rotations and root motion, chunk
    by chunk, at every frame their own skeleton needs or reduced keys."""

    def __init__(
        self,
        pxr: ModuleType,
        layer: StreamedLayer,
        plan: BodyPlan,
        keys: Keys,
        frames: int,
        timeline: Timeline | None = None,
    ) -> None:
        self.pxr, self.layer, self.plan, self.keys = pxr, layer, plan, keys
        Sdf = pxr.Sdf
        self.rotation_paths, self.translate_paths, self.turn_paths = [], [], []
        for name in plan.names:
            skel = f"/World/{name}/{part(name, 'skeleton')}"
            self.rotation_paths.append(Sdf.Path(f"{skel}/{part(name, 'animation')}.rotations"))
            self.translate_paths.append(Sdf.Path(f"/World/{name}.xformOp:translate"))
            self.turn_paths.append(Sdf.Path(f"/World/{name}.xformOp:rotateZ"))
        self.rotations = JointRotations(plan.skeleton.parents, plan.bodies)
        count, joints = plan.bodies.shape
        members = plan.members
        if timeline is None:
            self.samples = np.ones((frames, count), dtype=bool)
            self.heading = np.full((frames, count), np.nan)
            self.turns = np.zeros(count, dtype=bool)
        else:
            self.samples = timeline.samples[:, members]
            self.heading = timeline.heading[:, members]
            self.turns = timeline.turns[members]
        self.turning = np.flatnonzero(self.turns)
        self.tally = ChunkTally(count, joints, int(self.samples.sum()))
        self.previous: tuple[np.ndarray, np.ndarray] | None = None  # last frame: (q, root)
        self.yaw = np.zeros(count)  # the last frame's heading written (unwrapped)

    def add(self, first: int, chunk: Take) -> tuple[np.ndarray, np.ndarray]:
        """Samples for the chunk's frames (`first` on); returns the root translations
        (n, C, 3) as written (as USD interpolates them between reduced keys) and the
        headings (n, C, radians; 0 for a creature that does not turn)."""
        n = chunk.frames
        yaw = self._headings(first, chunk)
        turned = yaw if len(self.turning) else None
        root = chunk.pos[:, self.plan.bodies[:, 0]].astype(np.float64)  # (n, C, 3)
        samples = self.samples[first : first + n]
        if self.keys.mode == "all":  # the rotations of the creature-frames sampled only
            rows, columns = np.nonzero(samples)
            at = None if turned is None else turned[rows, columns]
            local = np.zeros((n, *self.plan.bodies.shape, 4))
            local[rows, columns] = self.rotations.local_at(chunk.quat, rows, columns, at)
            self._write(first, local, root, yaw, samples, None)
            self.tally.every(samples)
            return root, yaw
        local = self.rotations.local(chunk.quat, turned)
        self.previous, previous = (local[-1], root[-1]), self.previous
        return self._write_reduced(first, local, root, yaw, previous), yaw

    def _headings(self, first: int, chunk: Take) -> np.ndarray:
        """(n, C) the turning creatures' headings over the chunk: their stretch's ground
        frame's, else their mantle's yaw; unwrapped from the last frame written."""
        yaw = np.zeros((chunk.frames, len(self.turns)))
        if not len(self.turning):
            return yaw
        mantles = self.plan.bodies[self.turning, 0]
        q = chunk.quat[:, mantles].astype(np.float64)
        w, x, y, z = np.moveaxis(q, -1, 0)
        mantle = np.arctan2(2.0 * (w * z + x * y), w * w + x * x - y * y - z * z)
        ground = self.heading[first : first + chunk.frames, self.turning]
        raw = np.where(np.isnan(ground), mantle, ground)
        steps = np.diff(np.concatenate([self.yaw[None, self.turning], raw]), axis=0)
        steps = np.mod(steps + np.pi, 2.0 * np.pi) - np.pi  # the short way round
        yaw[:, self.turning] = self.yaw[self.turning] + np.cumsum(steps, axis=0)
        self.yaw = yaw[-1].copy()
        return yaw

    def _write(
        self,
        first: int,
        local: np.ndarray,
        root: np.ndarray,
        yaw: np.ndarray,
        rotation_keys: np.ndarray,
        root_keys: np.ndarray | None,
    ) -> None:
        """Rotations (xyzw quatf, a joint array per creature) where `rotation_keys` (n, C)
        says, root translations (float3) where `root_keys` does (None: every frame), and
        the turning creatures' rotateZ (degrees) every frame."""
        Gf, Vt = self.pxr.Gf, self.pxr.Vt
        xyzw = np.ascontiguousarray(local[..., [1, 2, 3, 0]], dtype=np.float32)
        rows = root.tolist()
        degrees = np.degrees(yaw).tolist()
        layer, size = self.layer, xyzw[0, 0].nbytes
        keyed = rotation_keys.tolist()
        turning = self.turning.tolist()
        with layer.batch():
            for row in range(len(local)):
                frame = first + row
                for c, (rotation_path, translate_path) in enumerate(
                    zip(self.rotation_paths, self.translate_paths, strict=True)
                ):
                    if keyed[row][c]:
                        value = Vt.QuatfArray.FromNumpy(xyzw[row, c])
                        layer.sample(rotation_path, frame, value, size)
                    if root_keys is None or root_keys[row, c]:
                        layer.sample(translate_path, frame, Gf.Vec3f(*rows[row][c]), 12)
                for c in turning:
                    layer.sample(self.turn_paths[c], frame, degrees[row][c], 4)

    def _write_reduced(
        self,
        first: int,
        local: np.ndarray,
        root: np.ndarray,
        yaw: np.ndarray,
        previous: tuple[np.ndarray, np.ndarray] | None,
    ) -> np.ndarray:
        """Keys each channel needs within the tolerance over this chunk (and the last
        frame of the one before, whose keys are written: every chunk's ends are kept),
        among the frames the own skeleton needs (the ends of each run of them kept)."""
        n0 = len(local)
        samples = self.samples[max(0, first - 1) : first + n0]
        if previous is not None:
            local = np.concatenate([previous[0][None], local])
            root = np.concatenate([previous[1][None], root])
        reduced = reduce_chunk(local, root, samples, self.keys.tolerance_deg)
        skip = 1 if previous is not None else 0  # the previous chunk wrote that frame
        keep, root_keep = reduced.rotation_keys[skip:], reduced.root_keys[skip:]
        rotation_keys: np.ndarray = np.any(keep, axis=2)
        self._write(first, reduced.rotations[skip:], root[skip:], yaw, rotation_keys, root_keep)
        self.tally.reduced(keep, root_keep, reduced.rotation_error_deg, reduced.root_error_m)
        return reduced.roots[skip:]


class ChunkTally:
    """Key counts and largest errors of a plan's creatures, added up chunk by chunk."""

    def __init__(self, creatures: int, joints: int, needed: int) -> None:
        self.joints = joints
        self.before = needed * (joints + 1)  # the creature-frames its own skeletons need
        self.after = 0
        self.samples = np.zeros(creatures, np.int64)  # frames with any key, per creature
        self.rotation_error = self.translation_error = 0.0

    def every(self, needed: np.ndarray) -> None:
        """A chunk's frames with every needed key kept: `needed` (n, C)."""
        self.after += int(needed.sum()) * (self.joints + 1)
        self.samples += needed.sum(axis=0)

    def reduced(
        self, rotation: np.ndarray, root: np.ndarray, rotation_error: float, moved: float
    ) -> None:
        """A chunk's kept keys, rotation (n, C, J) and root (n, C), and its errors."""
        self.after += int(rotation.sum() + root.sum())
        self.samples += (rotation.any(axis=2) | root).sum(axis=0)
        self.rotation_error = max(self.rotation_error, rotation_error)
        self.translation_error = max(self.translation_error, moved)


def key_report(
    animated: list[PlanSamples],
    frames: int,
    creatures: int = 0,
    sharing: int = 0,
    shared: int = 0,
    stretches: int = 0,
) -> KeyReport:
    """The key report over every plan's creatures' own animations (the frames they
    need); of `creatures`, `sharing` replay `stretches` stretches on `shared` clip
    animations (their keys not counted)."""
    tallies = [a.tally for a in animated]
    return KeyReport(
        before=sum(t.before for t in tallies),
        after=sum(t.after for t in tallies),
        max_rotation_error_deg=max((t.rotation_error for t in tallies), default=0.0),
        max_translation_error_m=max((t.translation_error for t in tallies), default=0.0),
        sample_frames=int(max((t.samples.max(initial=0) for t in tallies), default=0)),
        frames=frames,
        creatures=creatures,
        sharing=sharing,
        shared=shared,
        stretches=stretches,
    )
