"""Recording a live World into a `Take`, one frame at a time.

`TakeRecorder(world)` fixes the layout once (which store rows are which bodies and
suckers) and `capture()` copies the current frame with one gather per array; the
`record` system (`ecs_tentacles.record.systems.record`) calls it after physics_sync.
Everything else a take holds comes from the plugins' take tracks (the `TakeTracks`
entries: the locomotion plugin's goals, the fur plugin's guides, a user plugin's own),
recorded by kind (`export.track_recording`: `PointsTrack`, `CurvesTrack`); the standard
tracks no plugin fills are written empty, as the format asks (`ecs_tentacles.take.tracks`).
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any, Protocol, runtime_checkable

import numpy as np

from ecs_tentacles.components import Creature
from ecs_tentacles.events import Handler
from ecs_tentacles.export.frame_arrays import doubled, gather, widen
from ecs_tentacles.export.recording_stream import StreamedFrames
from ecs_tentacles.export.replay_recording import ReplayRecorder
from ecs_tentacles.export.take_tables import TakeTables
from ecs_tentacles.export.track_recording import CurvesTrack, PointsTrack
from ecs_tentacles.ground import ground_of
from ecs_tentacles.scene.plugins import former_keys
from ecs_tentacles.take import FORMAT, VERSION, Take, chunks
from ecs_tentacles.take import ground as take_ground
from ecs_tentacles.take import roster as take_roster
from ecs_tentacles.take.header_entries import HealthEvent
from ecs_tentacles.take.registries import (
    RecordingStarts,
    TakeTracks,
    TrackSource,
)
from ecs_tentacles.take.tracks import STANDARD, declared_problem

if TYPE_CHECKING:
    from ecs_tentacles.roster_change import RosterChange
    from ecs_tentacles.take.writer import TakeWriter
    from ecs_tentacles.world import World


@runtime_checkable
class Recording(Protocol):
    """What records a world into a take (the record plugin, which bakes add by name)."""

    def take(self) -> Take: ...

    def finish(self) -> Take: ...


def plugin_tracks(world: World) -> list[TrackSource]:
    """The take tracks of the world's plugins (`TakeTracks` entries), in plugin order."""
    return [source for tracks in world.registry(TakeTracks) for source in tracks(world)]


def before_recording(world: World) -> None:
    """Tell every plugin a recording starts (its `RecordingStarts` entries)."""
    for starts in world.registry(RecordingStarts):
        starts(world)


def scene_sha256(scene: dict[str, Any] | None) -> str:
    """SHA-256 of a scene's canonical JSON (sorted keys, no spaces; plugins by the keys
    they had first, `scene.plugins.former_keys`); '' without a scene."""
    if scene is None:
        return ""
    text = json.dumps(former_keys(scene), sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()


class TakeRecorder(TakeTables, StreamedFrames):
    """Copies a world's frames into growing float32 arrays; `take()` returns the Take.

    `fps` is the take's frame rate (the world's by default; a bake recording every
    k-th frame passes world fps / k). `scene_sha256` defaults to the hash of
    `world.scene`.
    """

    def __init__(
        self,
        world: World,
        *,
        fps: float | None = None,
        scene_sha256: str | None = None,
        capacity: int = 64,
        tracks: Sequence[TrackSource] = (),
        writer: TakeWriter | None = None,
    ):
        self.world = world
        self.writer = writer
        self._layout(world)
        self.tracks = self._tracks([*plugin_tracks(world), *tracks])
        self.header: dict[str, Any] = {
            "format": FORMAT,
            "version": VERSION,
            "scene": world.name,
            "scene_sha256": _sha(world) if scene_sha256 is None else scene_sha256,
            "seed": int(world.seed),
            "fps": float(fps if fps is not None else world.settings.fps),
            "sim_fps": float(world.settings.fps),
            "substeps": int(world.settings.substeps),
            "frames": 0,
            "creatures": self._creatures,
            "bodies": self._bodies,
            "suckers": self._suckers,
        }
        for recorder in self.tracks:
            self.header[recorder.track.key] = recorder.track.empty_header()
        declared = [r.track.declaration() for r in self.tracks if r.track not in STANDARD]
        if declared:
            self.header["tracks"] = declared
        # the terrain and obstacles as static meshes (nothing on the plane)
        ground, self._ground_arrays = take_ground.header_entry_and_arrays(ground_of(world))
        if ground is not None:
            self.header[take_ground.KEY] = ground
        bodies, suckers = len(self._rows), len(self._suckers)
        self._replay = ReplayRecorder(world, self.header, len(self._creatures))
        self._capacity_hint = capacity = max(1, capacity)
        if writer is not None:  # streamed: the arrays hold a chunk; the file the rest
            each = (
                bodies * 28
                + suckers * 13
                + (33 * len(self._creatures) if self._replay.active else 0)
            )
            writer.chunk_frames = capacity = chunks.chunk_frames(each)
        self._pos = np.empty((capacity, bodies, 3), np.float32)
        self._quat = np.empty((capacity, bodies, 4), np.float32)
        self._attached = np.empty((capacity, suckers), np.bool_)
        self._anchor = np.empty((capacity, suckers, 3), np.float32)
        self._replayed = (
            self._replay.empty(capacity, len(self._creatures)) if self._replay.active else {}
        )
        self._visible = np.empty((max(1, self._capacity_hint), len(self._creatures)), np.bool_)
        self._alive = np.ones(len(self._creatures), dtype=bool)
        self._base = 0  # frames handed to the writer (streamed)
        self._flushed_last: dict[str, np.ndarray] = {}  # the last frame handed over
        self._chunked_curves: list[CurvesTrack] | None = None  # streamed: decided at a flush
        self._changes = 0  # spawns and despawns while recording
        self._finished = False  # finish(): the arrays are the take's now
        self.count = 0
        # physics recoveries, marked on the take frame that follows them
        self._health: list[HealthEvent] = []
        world.events.on("creature_recovered", self._on_health("recovered"))
        world.events.on("creature_frozen", self._on_health("frozen"))

    def _tracks(self, sources: list[TrackSource]) -> list[PointsTrack | CurvesTrack]:
        """A recorder per track: the standard ones first (empty if no source fills them),
        then the others in order; a later source of the same key replaces an earlier."""
        standard = {track.key: track for track in STANDARD}
        chosen: dict[str, TrackSource | None] = dict.fromkeys(standard)
        for given in sources:
            key = given.track.key
            if key in standard and given.track != standard[key]:
                raise ValueError(f"take track {key!r} must be declared as {standard[key]}")
            chosen[key] = given
        declared = [s.track.declaration() for k, s in chosen.items() if s and k not in standard]
        problem = declared_problem({"tracks": declared})
        if problem:
            raise ValueError(f"a plugin's take track is not sound: {problem}")
        made: list[PointsTrack | CurvesTrack] = []
        for key, source in chosen.items():
            track = source.track if source else standard[key]
            kind = PointsTrack if track.kind == "points" else CurvesTrack
            made.append(kind(track, source.sample if source else None, self))
        return made

    def _on_health(self, what: str) -> Handler:
        def handler(*, creature: int, cause: str, **_: object) -> None:
            index = self.creature_index[creature]
            entry: HealthEvent = {"frame": self.count, "creature": index, "event": what,
                                  "cause": cause}  # fmt: skip
            self._health.append(entry)

        return handler

    # -- creatures that come and go --------------------------------------------------
    def roster_changed(self, change: RosterChange) -> None:
        """A creature was spawned (its bodies join the take, hidden before now) or
        despawned (its bodies hold their last pose, hidden from now on). Nothing once the
        recording has finished: the take holds the recorder's tables."""
        if self._finished:
            return
        world = self.world
        self._changes += 1
        self._replay.roster_changed()
        if not change.spawned:
            self._alive[self.creature_index[change.creature]] = False
            for rows, store in ((self._rows, "transforms"), (self._sucker_rows, "suckers")):
                moved = change.moved.get(store)
                if moved is not None:
                    live = rows >= 0
                    rows[live] = moved[rows[live]]
            return
        bodies, suckers = len(self._bodies), len(self._suckers)
        self._add_creatures(world, [(change.creature, world.component(change.creature, Creature))])
        self._alive = np.append(self._alive, True)
        new_rows = self._rows[bodies:]
        self._pos = widen(self._pos, world.transforms.pos[new_rows])
        self._quat = widen(self._quat, world.transforms.quat[new_rows])
        added = len(self._suckers) - suckers
        self._attached = widen(self._attached, np.zeros(added, np.bool_))
        self._anchor = widen(self._anchor, np.zeros((added, 3)))
        self._visible = widen(self._visible, np.zeros(1, np.bool_))
        widened = {"pos": world.transforms.pos[new_rows], "quat": world.transforms.quat[new_rows],
                   "anchor": np.zeros((added, 3), np.float32)}  # fmt: skip
        for name, value in widened.items():  # the frame handed over last, widened too
            if name in self._flushed_last:
                self._flushed_last[name] = np.concatenate([self._flushed_last[name], value])
        if self._replayed:
            self._replay.creature_added()
            blank = self._replay.empty(1, 1)
            self._replayed = {k: widen(v, blank[k][0]) for k, v in self._replayed.items()}

    def capture(self) -> None:
        """Append the world's current frame."""
        if self._finished:
            raise RuntimeError("this recording has finished (TakeRecorder.finish)")
        world, i = self.world, self.count - self._base
        if i == len(self._pos):
            if self.writer is not None:
                self._flush()
                i = 0
            else:
                self._grow()
        if self.count == len(self._visible):
            self._visible = doubled(self._visible)
        transforms, suckers = world.transforms, world.suckers
        if not self._changes:  # every body and sucker there, in store order
            bodies = self._rows if self._span is None else self._span  # a slice: no gather
            self._pos[i] = transforms.pos[bodies]
            self._quat[i] = transforms.quat[bodies]
            self._attached[i] = suckers.attached
            self._anchor[i] = suckers.anchor
        else:
            gather(self._pos, i, transforms.pos, self._rows, self._before("pos", i))
            gather(self._quat, i, transforms.quat, self._rows, self._before("quat", i))
            gather(self._attached, i, suckers.attached, self._sucker_rows, fill=False)
            gather(self._anchor, i, suckers.anchor, self._sucker_rows, self._before("anchor", i))
        if self._replayed:
            self._replay.capture(self._replayed, i, self.creature_index, self._rows)
        self._visible[self.count] = self._alive
        for recorder in self.tracks:
            recorder.capture(world)
        self.count += 1
        if self.writer is not None and self.writer.chunk_frames is None:
            self._size_chunks()

    @property
    def capacity(self) -> int:
        """Frames the arrays have room for now (they double when full; streamed: a chunk)."""
        return len(self._pos)

    @property
    def finished(self) -> bool:
        """Whether `finish()` ended the recording."""
        return self._finished

    @property
    def roster_changes(self) -> int:
        """Spawns and despawns since the recording started."""
        return self._changes

    def _grow(self) -> None:
        for name in ("_pos", "_quat", "_attached", "_anchor"):
            setattr(self, name, doubled(getattr(self, name)))
        self._replayed = {name: doubled(value) for name, value in self._replayed.items()}

    def take(self) -> Take:
        """The frames captured so far as a Take (copies; recording may go on)."""
        if self.writer is not None:
            raise RuntimeError("a streamed recording's frames are in its file")
        return self._take(copy=True)

    def finish(self) -> Take:
        """The frames captured, ending the recording: the take holds the recorder's own
        arrays and header, not copies (a bake holds its frames once, not twice; a
        capacity larger than the frames stays with them). `capture()` fails after."""
        if self.writer is not None:
            raise RuntimeError("a streamed recording ends with finish_stream()")
        self._finished = True
        return self._take(copy=False)

    def _header_and_tracks(
        self, n: int, copy: bool
    ) -> tuple[dict[str, Any], dict[str, np.ndarray]]:
        kept = np.copy if copy else np.asarray  # np.asarray: the array itself
        tracks: dict[str, np.ndarray] = {}
        for recorder in self.tracks:  # first: a curves track may name new owners
            if recorder not in (self._chunked_curves or ()):  # streamed: in the chunks
                tracks.update(recorder.arrays(n, copy))
        tracks.update({name: kept(a) for name, a in self._ground_arrays.items()})
        header = json.loads(json.dumps(self.header)) if copy else self.header  # deep copy
        header["frames"] = n
        events = [e for e in self._health if e["frame"] < n]
        header["health"] = {
            "recoveries": sum(e["event"] == "recovered" for e in events),
            "frozen": sum(e["event"] == "frozen" for e in events),
            "events": events,
        }
        if self._changes:
            header[take_roster.KEY] = {"changes": self._changes}
            tracks[take_roster.ARRAY] = kept(self._visible[:n])
        tracks.update(self._replay.static_arrays())  # in file order: after the roster
        return header, tracks

    def _take(self, copy: bool) -> Take:
        n = self.count
        kept = np.copy if copy else np.asarray  # np.asarray: the array itself
        header, tracks = self._header_and_tracks(n, copy)
        tracks.update({name: kept(value[:n]) for name, value in self._replayed.items()})
        return Take(
            header=header,
            pos=kept(self._pos[:n]),
            quat=kept(self._quat[:n]),
            sucker_attached=kept(self._attached[:n]),
            sucker_anchor=kept(self._anchor[:n]),
            tracks=tracks,
        )


def _sha(world: World) -> str:
    return scene_sha256(world.scene)
