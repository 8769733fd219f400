"""A take's creatures made ready for a skinned export: skeleton, mesh, animation, keys.

Both skinned writers (USD and glTF) start here, so they hold the same mesh, the same
joints and the same keys.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ecs_tentacles.skin.keys import (
    ROOT_TOLERANCE_M,
    KeyReport,
    angle_between,
    interpolate_points,
    interpolate_rotations,
    reduce_points,
    reduce_rotations,
)
from ecs_tentacles.skin.mesh import Detail, SkinMesh, creature_mesh
from ecs_tentacles.skin.skeleton import Animation, Skeleton, creature_animation, creature_skeleton
from ecs_tentacles.take import Take

KEY_MODES = ("all", "reduced")


@dataclass(frozen=True)
class Keys:
    """Which keys to write: every frame (`all`) or `reduced` within `tolerance_deg`."""

    mode: str = "all"
    tolerance_deg: float = 0.5

    def __post_init__(self) -> None:
        if self.mode not in KEY_MODES:
            raise ValueError(f"keys: must be one of {', '.join(KEY_MODES)}, got {self.mode!r}")
        if not self.tolerance_deg > 0:
            raise ValueError(f"key tolerance: must be > 0 degrees, got {self.tolerance_deg}")


@dataclass(frozen=True)
class Skin:
    """How to write skinned creatures: the mesh's level of detail and which keys to keep
    (what `ecs_tentacles.export.skinned`'s writers take)."""

    detail: Detail = field(default_factory=Detail)
    keys: Keys = field(default_factory=Keys)


@dataclass(frozen=True)
class SkinnedCreature:
    """One creature's rig: `rotation_keys` (F, J) and `translation_keys` (F,) mark the
    frames kept for each joint's rotation channel and the root's translation channel."""

    skeleton: Skeleton
    mesh: SkinMesh
    animation: Animation
    rotation_keys: np.ndarray
    translation_keys: np.ndarray

    @property
    def sample_frames(self) -> np.ndarray:
        """Frames where any channel has a key (a USD SkelAnimation samples all joints at once)."""
        return np.flatnonzero(self.rotation_keys.any(axis=1) | self.translation_keys)

    def rotations_at(self, frames: np.ndarray) -> np.ndarray:
        """Joint rotations (len(frames), J, 4) of the kept curves at `frames`."""
        curve = interpolate_rotations(self.animation.rotation, self.rotation_keys)
        rotations: np.ndarray = curve[frames]
        return rotations

    def translations_at(self, frames: np.ndarray) -> np.ndarray:
        """Joint translations (len(frames), J, 3): the root's kept curve, links' rest offsets."""
        out = self.animation.translation[frames].copy()
        root = interpolate_points(self.animation.translation[:, 0], self.translation_keys)
        out[:, 0] = root[frames]
        translations: np.ndarray = out
        return translations


def skinned_creatures(
    take: Take, detail: Detail | None = None, keys: Keys | None = None
) -> tuple[list[SkinnedCreature], KeyReport]:
    """Every creature of `take` rigged, and the key counts and errors over all of them."""
    tally = KeyTally(take.frames)
    creatures = [tally.add(rig_creature(take, index, detail, keys)) for index in
                 range(len(take.header["creatures"]))]  # fmt: skip
    return creatures, tally.report()


def rig_creature(
    take: Take, index: int, detail: Detail | None = None, keys: Keys | None = None
) -> SkinnedCreature:
    """Creature number `index` of `take` rigged: its skeleton, mesh, animation and keys
    (a writer that streams takes them one at a time, `KeyTally` adding up the report)."""
    keys = keys or Keys()
    skeleton = creature_skeleton(take, index)
    animation = creature_animation(skeleton, take)
    frames, joints = animation.rotation.shape[:2]
    if keys.mode == "all" or frames < 3:
        rotation_keys = np.ones((frames, joints), bool)
        translation_keys = np.ones(frames, bool)
    else:
        rotation_keys = reduce_rotations(animation.rotation, keys.tolerance_deg)
        translation_keys = reduce_points(animation.translation[:, 0], ROOT_TOLERANCE_M)
    return SkinnedCreature(
        skeleton=skeleton,
        mesh=creature_mesh(skeleton, detail),
        animation=animation,
        rotation_keys=rotation_keys,
        translation_keys=translation_keys,
    )


class KeyTally:
    """The key counts and largest errors over creatures added one at a time."""

    def __init__(self, frames: int) -> None:
        self.frames = frames
        self.before = self.after = self.samples = 0
        self.rotation_error = self.translation_error = 0.0

    def add(self, creature: SkinnedCreature) -> SkinnedCreature:
        """Count `creature`'s keys and errors in; returns it."""
        animation = creature.animation
        frames, joints = animation.rotation.shape[:2]
        self.samples = max(self.samples, len(creature.sample_frames))
        self.before += frames * (joints + 1)
        self.after += int(creature.rotation_keys.sum() + creature.translation_keys.sum())
        every = np.arange(frames)
        error = angle_between(creature.rotations_at(every), animation.rotation)
        self.rotation_error = max(self.rotation_error, float(error.max(initial=0.0)))
        moved = creature.translations_at(every)[:, 0] - animation.translation[:, 0]
        self.translation_error = max(
            self.translation_error, float(np.linalg.norm(moved, axis=1).max(initial=0.0))
        )
        return creature

    def report(self) -> KeyReport:
        """The report over every creature added."""
        return KeyReport(self.before, self.after, self.rotation_error, self.translation_error,
                         self.samples, self.frames)  # fmt: skip
