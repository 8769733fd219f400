"""Recording replayed creatures as what they are: clip, phase and root motion.

`ReplayRecorder` belongs to a `TakeRecorder`. Each captured frame it reads the level of
detail's replay (`ecs_tentacles.clips.replay`: every kinematic creature's clip kind,
phase, ground-frame place and heading) and marks each such creature with them where
the take's own reconstruction (`ecs_tentacles.take.replay.poses`) gives back the poses
the world shows, within `TOLERANCE` (positions) and a tenth of a degree; any other
creature-frame keeps its body poses (`replay_kind` -1). On terrain (the clips are
draped over the ground body by body) and without a replay it records nothing.

Reads: the physics roster's tiers, the replay's arrays and clips, the Transform store.
Writes: its own per-frame arrays and `header["replay"]` (clips as they are first used).
Whole-array work per frame; Python per creature only the first time it replays.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from ecs_tentacles.ground import ground_of
from ecs_tentacles.numeric.optional_kernels import OptionalKernels
from ecs_tentacles.physics.tiers import KINEMATIC
from ecs_tentacles.take import replay as take_replay

if TYPE_CHECKING:
    from ecs_tentacles.clips.clips import GaitClips
    from ecs_tentacles.clips.replay import ClipReplay
    from ecs_tentacles.physics.roster import Roster
    from ecs_tentacles.world import World

ROTATION = 1e-6  # 1 - |q . q'| allowed: about a tenth of a degree
# the check in one pass (numba), or None: numpy reconstructs the poses, then compares
KERNELS = OptionalKernels("ecs_tentacles.export.replay_check_kernel", "ECS_TENTACLES_REPLAY")


class ReplayRecorder:
    """The replay records of a take being recorded (see the module docstring)."""

    def __init__(self, world: World, header: dict[str, Any], creatures: int) -> None:
        self.world, self.header = world, header
        physics = getattr(world, "physics", None)
        self.lod = getattr(physics, "lod", None)
        self.active = (
            self.lod is not None
            and getattr(self.lod, "replay", None) is not None
            and ground_of(world).extent is None
        )
        self.clips: dict[int, np.ndarray] = {}  # take clip index -> (F, B, 7)
        self._clip_keys: dict[tuple[int, tuple[int, ...]], int] = {}
        self._owner = np.full(creatures, take_replay.PHYSICAL, dtype=np.int64)
        self._rows: dict[int, np.ndarray] = {}  # clip -> (creatures, B) body rows (-1: other)
        self._roster_size = -1
        self._take_of_roster = np.zeros(0, dtype=np.int64)
        if self.active:
            header[take_replay.KEY] = {"clips": [], "creatures": self._owner.tolist()}

    def empty(self, capacity: int, creatures: int) -> dict[str, np.ndarray]:
        """Per-frame arrays for `capacity` frames of `creatures` creatures."""
        return {
            "replay_kind": np.full((capacity, creatures), take_replay.PHYSICAL, np.int8),
            "replay_phase": np.zeros((capacity, creatures)),
            "replay_xy": np.zeros((capacity, creatures, 2)),
            "replay_heading": np.zeros((capacity, creatures)),
        }

    def creature_added(self) -> None:
        """A creature joined the take (spawned): no clip yet."""
        self._owner = np.append(self._owner, take_replay.PHYSICAL)
        self._roster_size = -1
        if self.active:
            self.header[take_replay.KEY]["creatures"] = self._owner.tolist()

    def roster_changed(self) -> None:
        self._roster_size = -1

    def capture(
        self,
        arrays: dict[str, np.ndarray],
        i: int,
        creature_index: dict[int, int],
        body_rows: np.ndarray,
    ) -> None:
        """Frame `i` of `arrays` from the world's replay; `body_rows` maps take bodies to
        Transform rows (-1: gone)."""
        kind_out = arrays["replay_kind"][i]
        kind_out[:] = take_replay.PHYSICAL
        replay = None if self.lod is None else self.lod.replay
        if not self.active or replay is None:
            return
        roster = self.world.physics.roster
        moving = np.flatnonzero(roster.tier == KINEMATIC)
        if not len(moving):
            return
        take_of = self._take_of(roster, creature_index)[moving]
        keep = take_of >= 0
        moving, take_of = moving[keep], take_of[keep]
        new = np.flatnonzero(self._owner[take_of] < 0)
        for k in new.tolist():
            self._assign(replay, roster, int(moving[k]), int(take_of[k]), body_rows)
        if len(new):
            self.header[take_replay.KEY]["creatures"] = self._owner.tolist()
        keep = self._owner[take_of] >= 0
        moving, take_of = moving[keep], take_of[keep]
        if not len(moving):
            return
        kind = replay.kind[moving].astype(np.int8)
        phase, xy, heading = replay.phase[moving], replay.xy[moving], replay.heading[moving]
        good = self._within(take_of, kind.astype(np.int64), phase, xy, heading, body_rows)
        at = take_of[good]
        kind_out[at] = kind[good]
        arrays["replay_phase"][i, at] = phase[good]
        arrays["replay_xy"][i, at] = xy[good]
        arrays["replay_heading"][i, at] = heading[good]

    def _within(
        self,
        take_of: np.ndarray,
        kind: np.ndarray,
        phase: np.ndarray,
        xy: np.ndarray,
        heading: np.ndarray,
        body_rows: np.ndarray,
    ) -> np.ndarray:
        """Whether each creature's reconstruction (`take.replay.poses`) is within the
        tolerance of what the world shows (False where a body has no Transform row)."""
        good = np.zeros(len(take_of), dtype=bool)
        owner = self._owner[take_of]
        transforms = self.world.transforms
        fast = KERNELS.get()
        if fast is None:
            found = take_replay.poses(
                self.header, self.clips, take_of, kind, phase, xy, heading, self._rows
            )
            for clip, (rows, pos, quat) in found.items():
                store = body_rows[rows]
                if (store < 0).any():
                    continue
                near = np.abs(pos - transforms.pos[store]).max(axis=(1, 2))
                dot = np.abs(np.einsum("kbi,kbi->kb", quat, transforms.quat[store]))
                good[owner == clip] = (near <= take_replay.TOLERANCE) & (
                    (1.0 - dot).max(axis=1) <= ROTATION
                )
            return good
        clips = self.header[take_replay.KEY]["clips"]
        for clip in np.unique(owner).tolist():
            mine = np.flatnonzero(owner == clip)
            store = body_rows[self._rows[clip][take_of[mine]]]
            if (store < 0).any():
                continue
            idle, crawl = (int(n) for n in clips[clip]["frames"])
            good[mine] = fast.replay_within(
                self.clips[clip], idle, crawl, kind[mine], phase[mine], xy[mine],
                heading[mine], store, transforms.pos, transforms.quat,
                take_replay.TOLERANCE, ROTATION,
            )  # fmt: skip
        return good

    def _take_of(self, roster: Roster, creature_index: dict[int, int]) -> np.ndarray:
        """Roster index -> take creature index (-1: not in the take), kept until the
        roster changes."""
        if self._roster_size != len(roster):
            entities = roster.entity.tolist()
            self._take_of_roster = np.array(
                [creature_index.get(int(e), -1) for e in entities], dtype=np.int64
            )
            self._roster_size = len(roster)
        return self._take_of_roster

    def _assign(
        self, replay: ClipReplay, roster: Roster, index: int, creature: int, body_rows: np.ndarray
    ) -> None:
        """Give take creature `creature` (roster `index`) its clip: its morphology's,
        bodies in take order; a clip is stored once per morphology and body order."""
        batch, row = roster.locate(index)
        clips: GaitClips = replay.clips_of(batch)
        mine = take_replay.body_rows(self.header["creatures"][creature])
        take_rows = body_rows[mine]
        batch_rows = np.asarray(batch.body_rows[row]).reshape(-1)
        if len(batch_rows) != len(take_rows) or (take_rows < 0).any():
            return
        order = np.argsort(batch_rows)
        at = np.searchsorted(batch_rows[order], take_rows)
        if not np.array_equal(batch_rows[order][np.minimum(at, len(order) - 1)], take_rows):
            return
        perm = order[at]
        key = (int(batch.index), tuple(perm.tolist()))
        clip = self._clip_keys.get(key)
        if clip is None:
            clip = self._clip_keys[key] = len(self.clips)
            pose = np.concatenate(
                [np.concatenate([c.pos, c.quat], axis=-1) for c in (clips.idle, clips.crawl)]
            )
            self.clips[clip] = np.ascontiguousarray(pose[:, perm], dtype=np.float64)
            self.header[take_replay.KEY]["clips"].append(
                {
                    "bodies": len(perm),
                    "dt": float(clips.crawl.dt),
                    "frames": [int(clips.idle.frames), int(clips.crawl.frames)],
                }
            )
        self._owner[creature] = clip
        table = self._rows.setdefault(clip, np.full((0, len(mine)), -1, dtype=np.int64))
        if len(table) < len(self._owner):
            grown = np.full((len(self._owner), len(mine)), -1, dtype=np.int64)
            grown[: len(table)] = table
            self._rows[clip] = table = grown
        table[creature] = mine

    def static_arrays(self) -> dict[str, np.ndarray]:
        """The clips' frames, by file name."""
        return {take_replay.clip_array(i): pose for i, pose in self.clips.items()}
