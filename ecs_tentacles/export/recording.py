"""Recording a live World into a `Take`, one frame at a time.

`TakeRecorder(world)` fixes the layout once (which store rows are which bodies and
suckers) and `capture()` copies the current frame with one gather per array; the
`record` system (`ecs_tentacles.systems.record.record`) calls it after physics_sync.
Everything else a take holds comes from the plugins' take tracks
(`Plugin.take_tracks`: the locomotion plugin's goals, the fur plugin's guides, a
user plugin's own), recorded by kind (`PointsTrack`, `CurvesTrack`); the standard
tracks no plugin fills are written empty, as the format asks (`ecs_tentacles.take_tracks`).
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any, Protocol, runtime_checkable

import numpy as np

from ecs_tentacles import take_ground
from ecs_tentacles.components import Creature, Link, Tentacle, Transform
from ecs_tentacles.ground import ground_of
from ecs_tentacles.plugin import CurvesFrame, PointsFrame, TrackSource
from ecs_tentacles.take import FORMAT, VERSION, Take
from ecs_tentacles.take_tracks import STANDARD, TakeTrack, declared_problem

if TYPE_CHECKING:
    from ecs_tentacles.world import World


@runtime_checkable
class Recording(Protocol):
    """What records a world into a take (the record plugin, which bakes add by name)."""

    def take(self) -> Take: ...


def plugin_tracks(world: World) -> list[TrackSource]:
    """The take tracks of the world's plugins, in plugin order."""
    return [source for plugin in world.plugins for source in plugin.take_tracks(world)]


def before_recording(world: World) -> None:
    """Tell every plugin a recording starts (`Plugin.before_recording`)."""
    for plugin in world.plugins:
        plugin.before_recording(world)


def scene_sha256(scene: dict[str, Any] | None) -> str:
    """SHA-256 of a scene's canonical JSON (sorted keys, no spaces); '' without a scene."""
    if scene is None:
        return ""
    text = json.dumps(scene, sort_keys=True, separators=(",", ":"))
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
    ):
        self.world = world
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
        capacity = max(1, capacity)
        self._pos = np.empty((capacity, bodies, 3), np.float32)
        self._quat = np.empty((capacity, bodies, 4), np.float32)
        self._attached = np.empty((capacity, suckers), np.bool_)
        self._anchor = np.empty((capacity, suckers, 3), np.float32)
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
        self._creatures: list[dict[str, Any]] = []
        self._bodies: list[dict[str, Any]] = []
        rows: list[int] = []
        by_entity = sorted(world.query(Creature), key=lambda item: item[1].row)
        # creature entity -> its index in the take (tracks name their owners by it)
        self.creature_index = {entity: i for i, (entity, _) in enumerate(by_entity)}
        for index, (entity, creature) in enumerate(by_entity):
            name = creature.name
            entry: dict[str, Any] = {"name": name, "mantle": len(rows), "tentacles": []}
            rows.append(world.component(entity, Transform).row)
            self._bodies.append(_body(f"{name}/mantle", index, "cylinder", "Z", creature))
            for tentacle_entity in creature.tentacles:
                tentacle = world.component(tentacle_entity, Tentacle)
                chain = []
                for link_entity in tentacle.links:
                    link = world.component(link_entity, Link)
                    chain.append(len(rows))
                    rows.append(world.component(link_entity, Transform).row)
                    body = f"{name}/tentacles/t{tentacle.index}/link{link.index}"
                    self._bodies.append(_body(body, index, "capsule", "X", link))
                entry["tentacles"].append(chain)
            self._creatures.append(entry)
        self._rows = np.asarray(rows, dtype=np.int64)
        body_of_row = {row: i for i, row in enumerate(rows)}
        self._suckers: list[dict[str, Any]] = []
        seen: dict[int, int] = {}
        suckers = world.suckers
        for link_row, offset in zip(
            suckers.link_row.tolist(), suckers.offset.tolist(), strict=True
        ):
            carrier = body_of_row[link_row]
            n = seen[carrier] = seen.get(carrier, -1) + 1
            name = f"{self._bodies[carrier]['name']}/sucker{n}"
            self._suckers.append({"name": name, "body": carrier, "offset": offset})

    def capture(self) -> None:
        """Append the world's current frame."""
        world, i = self.world, self.count
        if i == len(self._pos):
            self._grow()
        transforms = world.transforms
        self._pos[i] = transforms.pos[self._rows]
        self._quat[i] = transforms.quat[self._rows]
        self._attached[i] = world.suckers.attached
        self._anchor[i] = world.suckers.anchor
        for recorder in self.tracks:
            recorder.capture(world)
        self.count += 1

    def _grow(self) -> None:
        for name in ("_pos", "_quat", "_attached", "_anchor"):
            old = getattr(self, name)
            grown = np.empty((2 * len(old), *old.shape[1:]), old.dtype)
            grown[: len(old)] = old
            setattr(self, name, grown)

    def take(self) -> Take:
        """The frames captured so far as a Take (copies; recording may go on)."""
        n = self.count
        header = json.loads(json.dumps(self.header))  # a deep copy
        header["frames"] = n
        events = [e for e in self._health if e["frame"] < n]
        header["health"] = {
            "recoveries": sum(e["event"] == "recovered" for e in events),
            "frozen": sum(e["event"] == "frozen" for e in events),
            "events": events,
        }
        tracks: dict[str, np.ndarray] = {}
        for recorder in self.tracks:
            tracks.update(recorder.arrays(n))
        tracks.update({name: a.copy() for name, a in self._ground_arrays.items()})
        return Take(
            header=header,
            pos=self._pos[:n].copy(),
            quat=self._quat[:n].copy(),
            sucker_attached=self._attached[:n].copy(),
            sucker_anchor=self._anchor[:n].copy(),
            tracks=tracks,
        )


class PointsTrack:
    """Records a points track: locators appear (in creature, then `order` order, never
    in entity-id order, which depends on which other creatures the world holds: a
    shard of a bake), keep their first position, and are live while sampled."""

    def __init__(self, track: TakeTrack, sample: Any, recorder: TakeRecorder):
        self.track, self.sample, self.recorder = track, sample, recorder
        self.columns: dict[int, int] = {}  # key -> column
        self.positions: list[np.ndarray] = []
        self.alive: list[list[int]] = []  # per frame, the live columns

    def capture(self, world: World) -> None:
        frame: PointsFrame | None = self.sample(world) if self.sample else None
        if frame is None:
            self.alive.append([])
            return
        index = self.recorder.creature_index
        items = list(
            zip(frame.keys, frame.creatures, frame.order, range(len(frame.keys)), strict=True)
        )
        new = [item for item in items if item[0] not in self.columns]
        for key, creature, _, i in sorted(new, key=lambda it: (index[it[1]], it[2])):
            self._add(key, index[creature], frame.positions[i], frame.radii[i])
        self.alive.append(sorted(self.columns[key] for key in frame.keys))

    def _add(self, key: int, creature: int, position: Any, radius: float) -> None:
        entries = self.recorder.header[self.track.key]
        self.columns[key] = len(self.positions)
        number = sum(entry["creature"] == creature for entry in entries)
        owner = self.recorder.header["creatures"][creature]["name"]
        name = f"{owner}/{self.track.folder}/{self.track.item}{number}"
        entries.append({"name": name, "creature": creature, "radius": radius})
        self.positions.append(np.asarray(position, dtype=np.float64))

    def arrays(self, frames: int) -> dict[str, np.ndarray]:
        count = len(self.positions)
        live = np.zeros((frames, count), np.bool_)
        for frame, alive in enumerate(self.alive[:frames]):
            live[frame, alive] = True
        where, shown = self.track.arrays
        return {where: np.array(self.positions, np.float32).reshape(count, 3), shown: live}


class CurvesTrack:
    """Records a curves track: every frame the same curves (shape fixed by the first)."""

    def __init__(self, track: TakeTrack, sample: Any, recorder: TakeRecorder):
        self.track, self.sample, self.recorder = track, sample, recorder
        self.points: list[np.ndarray] = []
        self.widths: list[np.ndarray] = []

    def capture(self, world: World) -> None:
        frame: CurvesFrame | None = self.sample(world) if self.sample else None
        key = self.track.key
        if frame is None:
            if self.points:
                raise ValueError(f"take track {key!r} disappeared during the recording")
            return
        points = np.asarray(frame.points, dtype=np.float32)
        widths = np.broadcast_to(np.asarray(frame.widths, dtype=np.float32), points.shape[:2])
        if points.ndim != 3 or points.shape[2] != 3:
            raise ValueError(f"{key} points must be (curves, points, 3), got {points.shape}")
        if self.points and points.shape != self.points[0].shape:
            raise ValueError(f"{key} changed shape: {self.points[0].shape} -> {points.shape}")
        if not self.points:
            owners = [self.recorder.creature_index.get(int(e), -1) for e in frame.creatures]
            self.recorder.header[key] = {"creatures": owners}
        self.points.append(points)
        self.widths.append(np.array(widths))

    def arrays(self, frames: int) -> dict[str, np.ndarray]:
        if not self.points:
            return {}
        first, second = self.track.arrays
        return {first: np.stack(self.points[:frames]), second: np.stack(self.widths[:frames])}


def _body(name: str, creature: int, shape: str, axis: str, part: Any) -> dict[str, Any]:
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
