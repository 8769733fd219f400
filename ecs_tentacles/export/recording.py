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
from typing import TYPE_CHECKING, Any, Literal, Protocol, runtime_checkable

import numpy as np

from ecs_tentacles.components import Creature, Link, Tentacle, Transform
from ecs_tentacles.export.frame_arrays import doubled, gather, resized_frames, widen
from ecs_tentacles.export.replay_recording import ReplayRecorder
from ecs_tentacles.export.track_recording import CurvesTrack, PointsTrack
from ecs_tentacles.ground import ground_of
from ecs_tentacles.numeric.rows import ordinals, run_slice
from ecs_tentacles.scene.plugins import former_keys
from ecs_tentacles.take import FORMAT, VERSION, Take, TakeError, chunks
from ecs_tentacles.take import ground as take_ground
from ecs_tentacles.take import replay as take_replay
from ecs_tentacles.take import roster as take_roster
from ecs_tentacles.take.entries import data_problem
from ecs_tentacles.take.registries import (
    RecordingStarts,
    TakeTracks,
    TrackSource,
)
from ecs_tentacles.take.tracks import STANDARD, declared_problem

if TYPE_CHECKING:
    from ecs_tentacles.roster_change import RosterChange
    from ecs_tentacles.take.header_entries import HeaderBody, HeaderCreature, HeaderSucker
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


class TakeRecorder:
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
        self._health: list[dict[str, Any]] = []
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

    def _on_health(self, what: str) -> Any:
        def handler(*, creature: int, cause: str, **_: Any) -> None:
            index = self.creature_index[creature]
            entry = {"frame": self.count, "creature": index, "event": what, "cause": cause}
            self._health.append(entry)

        return handler

    def _layout(self, world: World) -> None:
        """Body and sucker tables in take order: creature by creature, mantle then links."""
        self._creatures: list[HeaderCreature] = []
        self._bodies: list[HeaderBody] = []
        self._suckers: list[HeaderSucker] = []
        self.creature_index: dict[int, int] = {}  # creature entity -> its index in the take
        self._rows = np.zeros(0, dtype=np.int64)  # take body -> Transform row (-1: gone)
        self._sucker_rows = np.zeros(0, dtype=np.int64)  # take sucker -> Sucker row
        by_row = sorted(world.query(Creature), key=lambda item: item[1].row)
        self._add_creatures(world, by_row)

    def _add_creatures(self, world: World, creatures: Sequence[tuple[int, Creature]]) -> None:
        """Append creatures to the take's tables: each one's mantle, then its links
        tentacle by tentacle; then their suckers, creature by creature, in store order."""
        first = len(self._bodies)
        rows: list[int] = []
        for entity, creature in creatures:
            rows += self._add_bodies(world, entity, creature)
        added = np.asarray(rows, dtype=np.int64)
        self._rows = np.concatenate([self._rows, added])
        # the bodies as one run of store rows, or None (what a roster change leaves is
        # gathered row by row: `_changes`)
        self._span = run_slice(self._rows)
        self._add_suckers(world, added, first)

    def _add_bodies(self, world: World, entity: int, creature: Creature) -> list[int]:
        """Append one creature's bodies to the take's tables; their Transform rows."""
        index = self.creature_index[entity] = len(self._creatures)
        world.kept_names.add(name := creature.name)  # a later spawn of it gets a suffix
        first = len(self._bodies)
        rows = [world.component(entity, Transform).row]
        entry: HeaderCreature = {"name": name, "mantle": first, "tentacles": []}
        self._bodies.append(_body(f"{name}/mantle", index, "cylinder", "Z", creature))
        for tentacle_entity in creature.tentacles:
            tentacle = world.component(tentacle_entity, Tentacle)
            chain = []
            for link_entity in tentacle.links:
                link = world.component(link_entity, Link)
                chain.append(first + len(rows))
                rows.append(world.component(link_entity, Transform).row)
                body = f"{name}/tentacles/t{tentacle.index}/link{link.index}"
                self._bodies.append(_body(body, index, "capsule", "X", link))
            entry["tentacles"].append(chain)
        self._creatures.append(entry)
        return rows

    def _add_suckers(self, world: World, rows: np.ndarray, first: int) -> None:
        """Append the suckers on the take's bodies `first...` (at Transform `rows`):
        creature by creature, each creature's in store order, named by their body."""
        suckers = world.suckers
        body_of_row = np.full(len(world.transforms), -1, dtype=np.int64)
        body_of_row[rows] = np.arange(first, first + len(rows))
        carrier = body_of_row[suckers.link_row]
        mine = np.flatnonzero(carrier >= 0)
        owner = np.array([body["creature"] for body in self._bodies[first:]], dtype=np.int64)
        mine = mine[np.argsort(owner[carrier[mine] - first], kind="stable")]
        carriers = carrier[mine]
        number = ordinals(carriers)  # each sucker's place among its body's
        offsets = suckers.offset[mine].tolist()
        for body, n, offset in zip(carriers.tolist(), number.tolist(), offsets, strict=True):
            name = f"{self._bodies[body]['name']}/sucker{n}"
            self._suckers.append({"name": name, "body": body, "offset": offset})
        self._sucker_rows = np.concatenate([self._sucker_rows, mine])

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

    def _size_chunks(self) -> None:
        """Frames per chunk from the first frame's bytes of every chunked array (the
        curves tracks sampled by now among them), as `Take.save` counts them."""
        assert self.writer is not None
        frame = sum(a[:1].nbytes for a in self._chunk_arrays(1).values())
        for track in self.tracks:
            if isinstance(track, CurvesTrack):
                frame += sum(a[:1].nbytes for a in track.arrays(1, copy=False).values())
        self.writer.chunk_frames = per = chunks.chunk_frames(frame)
        for name in ("_pos", "_quat", "_attached", "_anchor"):
            setattr(self, name, resized_frames(getattr(self, name), per))
        self._replayed = {k: resized_frames(v, per) for k, v in self._replayed.items()}

    def _before(self, name: str, i: int) -> np.ndarray | None:
        """Frame `i - 1` of chunked array `name` (`_pos`, ...): in the array, or the last
        frame handed to the writer when `i` starts a chunk; None before the first."""
        if i:
            return np.asarray(getattr(self, f"_{name}")[i - 1])
        return self._flushed_last.get(name)

    def _chunk_arrays(self, frames: int) -> dict[str, np.ndarray]:
        """The chunked arrays' first `frames` frames, by file name."""
        out = {
            "pos": self._pos[:frames],
            "quat": self._quat[:frames],
            "sucker_attached": self._attached[:frames],
            "sucker_anchor": self._anchor[:frames],
        }
        out.update({name: value[:frames] for name, value in self._replayed.items()})
        return out

    def _flush(self) -> None:
        """Hand the frames held to the writer (streamed recording). The first time, the
        curves tracks recording by then are chunked too (`header["chunked"]`)."""
        assert self.writer is not None
        held = self.count - self._base
        if not held:
            return
        if self._chunked_curves is None:
            self._chunked_curves = [t for t in self.tracks if isinstance(t, CurvesTrack)
                                    and t.flush(self._base) is not None]  # fmt: skip
            curves = [a for t in self._chunked_curves for a in t.track.arrays]
            self.header["chunked"] = [*self._chunk_arrays(0), *curves]
            points = [t.track.arrays[0] for t in self._chunked_curves]
            self.writer.quantised = dict.fromkeys(points, chunks.STEP)  # as `Take.save` does
        arrays = self._chunk_arrays(held)
        for track in self._chunked_curves:
            arrays.update(track.flush(self.count) or {})
        numbers = {k: v for k, v in arrays.items() if not k.startswith("replay_")}
        problem = data_problem(numbers, [t.track for t in self._chunked_curves], self._base)
        if problem:  # a plugin's NaN: nobody could read the take
            raise TakeError(f"{self.writer.path}: cannot write this take: {problem}")
        # a creature gone keeps its last pose: remembered across the chunk boundary
        self._flushed_last = {
            name: getattr(self, f"_{name}")[held - 1].copy() for name in ("pos", "quat", "anchor")
        }
        self.writer.add_frames(take_replay.blanked(self.header, arrays, in_place=True))
        self._base = self.count

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

    def finish_stream(self) -> dict[str, Any]:
        """End a streamed recording: the last frames, the arrays without chunks and the
        header go to the writer (its file is renamed into place when its block ends);
        returns the header as written."""
        assert self.writer is not None, "finish_stream() ends a streamed recording"
        self._flush()
        self._finished = True
        header, tracks = self._header_and_tracks(self.count, copy=False)
        self.writer.finish(header, tracks)
        return {**header, "frames": self.writer.frames, "chunk_frames": self.writer.chunk_frames}

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


def _body(
    name: str,
    creature: int,
    shape: Literal["cylinder", "capsule"],
    axis: Literal["X", "Z"],
    part: Creature | Link,
) -> HeaderBody:
    if isinstance(part, Creature):
        radius, length = part.mantle_radius, part.mantle_height
    else:
        radius, length = part.radius, part.length
    return {
        "name": name,
        "creature": creature,
        "shape": shape,
        "axis": axis,
        "radius": float(radius),
        "length": float(length),
    }


def _sha(world: World) -> str:
    return scene_sha256(world.scene)
