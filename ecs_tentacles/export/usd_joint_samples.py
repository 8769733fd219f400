"""The time samples of a skinned USD's creatures, chunk of frames by chunk.

    samples = PlanSamples(pxr, layer, plan, keys, frames)    # one body plan's creatures
    for first, chunk in source.chunks():
        origin = samples.add(first, chunk)                   # root positions as written

Per creature and frame: the joints' rotations (one quatf array on its SkelAnimation,
the root's being the mantle's world rotation) and the root's position (the SkelRoot's
translate). Rotations come from `ecs_tentacles.skin.streamed` for every creature of a
plan at once. With `Keys("reduced")` each chunk is reduced on its own with the last
frame of the chunk before as its first (a key already written: every chunk's ends are
kept), so the error stays within the tolerance at every frame, the seams included; the
frames kept are those where any joint of a creature has a key (a SkelAnimation samples
all its joints at once). `ChunkTally` adds up the key report.

Reads chunks of a take; writes time samples through a `StreamedLayer`.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ecs_tentacles.export.names import part
from ecs_tentacles.export.usd_layer import StreamedLayer
from ecs_tentacles.export.usd_plans import BodyPlan
from ecs_tentacles.skin.keys import (
    ROOT_TOLERANCE_M,
    KeyReport,
    angle_between,
    interpolate_points,
    interpolate_rotations,
    reduce_points,
    reduce_rotations,
)
from ecs_tentacles.skin.rig import Keys
from ecs_tentacles.skin.streamed import JointRotations
from ecs_tentacles.take import Take


class PlanSamples:
    """The time samples of one body plan's creatures: rotations and root translations,
    chunk by chunk, every frame or reduced keys."""

    def __init__(self, pxr: Any, layer: StreamedLayer, plan: BodyPlan, keys: Keys, frames: int):
        self.pxr, self.layer, self.plan, self.keys = pxr, layer, plan, keys
        Sdf = pxr.Sdf
        self.rotation_paths, self.translate_paths = [], []
        for name in plan.names:
            skel = f"/World/{name}/{part(name, 'skeleton')}"
            self.rotation_paths.append(Sdf.Path(f"{skel}/{part(name, 'animation')}.rotations"))
            self.translate_paths.append(Sdf.Path(f"/World/{name}.xformOp:translate"))
        self.rotations = JointRotations(plan.skeleton.parents, plan.bodies)
        count, joints = plan.bodies.shape
        self.tally = ChunkTally(count, joints, frames)
        self.previous: tuple[np.ndarray, np.ndarray] | None = None  # last frame: (q, root)

    def add(self, first: int, chunk: Take) -> np.ndarray:
        """Samples for the chunk's frames (`first` on); returns the root translations
        (n, C, 3) as written (as USD interpolates them between reduced keys)."""
        local = self.rotations.local(chunk.quat)  # (n, C, J, 4)
        root = chunk.pos[:, self.plan.bodies[:, 0]].astype(np.float64)  # (n, C, 3)
        self.previous, previous = (local[-1], root[-1]), self.previous
        if self.keys.mode == "all":
            self._write(first, local, root, None, None)
            return root
        return self._write_reduced(first, local, root, previous)

    def _write(
        self,
        first: int,
        local: np.ndarray,
        root: np.ndarray,
        rotation_keys: np.ndarray | None,
        root_keys: np.ndarray | None,
    ) -> None:
        """Rotations (xyzw quatf, a joint array per creature) and root translations at
        the chunk's frames, or where the key masks (n, C) say."""
        Gf, Vt = self.pxr.Gf, self.pxr.Vt
        xyzw = np.ascontiguousarray(local[..., [1, 2, 3, 0]], dtype=np.float32)
        rows = root.tolist()
        layer, size = self.layer, xyzw[0, 0].nbytes
        with layer.batch():
            for row in range(len(local)):
                frame = first + row
                for c, (rotation_path, translate_path) in enumerate(
                    zip(self.rotation_paths, self.translate_paths, strict=True)
                ):
                    if rotation_keys is None or rotation_keys[row, c]:
                        value = Vt.QuatfArray.FromNumpy(xyzw[row, c])
                        layer.sample(rotation_path, frame, value, size)
                    if root_keys is None or root_keys[row, c]:
                        layer.sample(translate_path, frame, Gf.Vec3d(*rows[row][c]), 24)
        if rotation_keys is None:
            self.tally.every(len(local))

    def _write_reduced(
        self,
        first: int,
        local: np.ndarray,
        root: np.ndarray,
        previous: tuple[np.ndarray, np.ndarray] | None,
    ) -> np.ndarray:
        """Keys each channel needs within the tolerance over this chunk (and the last
        frame of the one before, whose keys are written: every chunk's ends are kept)."""
        if previous is not None:
            local = np.concatenate([previous[0][None], local])
            root = np.concatenate([previous[1][None], root])
        n, count, joints = local.shape[:3]
        flat = local.reshape(n, count * joints, 4)
        if n < 3:
            keep = np.ones((n, count * joints), bool)
            root_keep = np.ones((n, count), bool)
        else:
            keep = reduce_rotations(flat, self.keys.tolerance_deg)
            root_keep = np.stack(
                [reduce_points(root[:, c], ROOT_TOLERANCE_M) for c in range(count)], axis=1
            )
        curve = interpolate_rotations(flat, keep).reshape(local.shape)
        error = float(angle_between(curve.reshape(flat.shape), flat).max(initial=0.0))
        paths = np.stack(
            [interpolate_points(root[:, c], root_keep[:, c]) for c in range(count)], axis=1
        )
        moved = float(np.linalg.norm(paths - root, axis=-1).max(initial=0.0))
        keep = keep.reshape(n, count, joints)
        skip = 1 if previous is not None else 0  # the previous chunk wrote that frame
        rotation_keys: np.ndarray = np.any(keep, axis=2)[skip:]
        self._write(first, curve[skip:], root[skip:], rotation_keys, root_keep[skip:])
        self.tally.reduced(keep[skip:], root_keep[skip:], error, moved)
        return paths[skip:]


class ChunkTally:
    """Key counts and largest errors of a plan's creatures, added up chunk by chunk."""

    def __init__(self, creatures: int, joints: int, frames: int) -> None:
        self.joints = joints
        self.before = creatures * frames * (joints + 1)
        self.after = 0
        self.samples = np.zeros(creatures, np.int64)  # frames with any key, per creature
        self.rotation_error = self.translation_error = 0.0

    def every(self, frames: int) -> None:
        """A chunk of `frames` frames with every key kept."""
        self.after += frames * len(self.samples) * (self.joints + 1)
        self.samples += frames

    def reduced(
        self, rotation: np.ndarray, root: np.ndarray, rotation_error: float, moved: float
    ) -> None:
        """A chunk's kept keys, rotation (n, C, J) and root (n, C), and its errors."""
        self.after += int(rotation.sum() + root.sum())
        self.samples += (rotation.any(axis=2) | root).sum(axis=0)
        self.rotation_error = max(self.rotation_error, rotation_error)
        self.translation_error = max(self.translation_error, moved)


def key_report(
    animated: list[PlanSamples], frames: int, creatures: int = 0, sharing: int = 0, shared: int = 0
) -> KeyReport:
    """The key report over every plan's creatures with their own animation; of
    `creatures`, `sharing` bind one of `shared` clip animations (their keys not counted)."""
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
    )
