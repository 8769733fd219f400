"""Recording a take's tracks frame by frame (`export.recording.TakeRecorder` makes one
per track a plugin adds, `TakeTracks`): points tracks (locators that appear and stay
where they first appeared, live while sampled) and curves tracks (polylines posed every
frame). Each writes its part of the take's header and its two arrays.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Protocol

import numpy as np

if TYPE_CHECKING:
    from ecs_tentacles.take.registries import CurvesFrame, PointsFrame
    from ecs_tentacles.take.tracks import TakeTrack
    from ecs_tentacles.world import World


class Recorder(Protocol):
    """What a track reads of the take recorder it belongs to."""

    header: dict[str, Any]
    creature_index: dict[int, int]  # creature entity -> its index in the take
    count: int  # frames captured so far

    @property
    def roster_changes(self) -> int: ...


class PointsTrack:
    """Records a points track: locators appear (in creature, then `order` order, never
    in entity-id order, which depends on which other creatures the world holds: a
    shard of a bake), keep their first position, and are live while sampled.

    A frame costs array work over its locators (a frame like the last one: nothing more
    than comparing its keys); only locators that appear cost Python work, once each.
    """

    def __init__(self, track: TakeTrack, sample: Any, recorder: Recorder):
        self.track, self.sample, self.recorder = track, sample, recorder
        self.positions: list[np.ndarray] = []
        self.alive: list[np.ndarray] = []  # per frame, the live columns (shared while equal)
        self._keys = np.zeros(0, dtype=np.int64)  # every key seen, sorted ...
        self._columns = np.zeros(0, dtype=np.int64)  # ... and its column
        self._numbers: dict[int, int] = {}  # take creature index -> its locators so far
        self._last: tuple[np.ndarray, np.ndarray] = (_NONE, _NONE)  # keys, live columns

    def capture(self, world: World) -> None:
        frame: PointsFrame | None = self.sample(world) if self.sample else None
        keys = _NONE if frame is None else np.asarray(frame.keys, dtype=np.int64).reshape(-1)
        if np.array_equal(keys, self._last[0]):
            self.alive.append(self._last[1])
            return
        new = np.flatnonzero(~_found(self._keys, keys))
        if frame is not None and len(new):
            self._add(frame, new)
        columns = self._columns[np.searchsorted(self._keys, keys)]
        self._last = (keys, np.sort(columns))
        self.alive.append(self._last[1])

    def _add(self, frame: PointsFrame, new: np.ndarray) -> None:
        """Columns and header entries for the locators `new` (indices into `frame`)."""
        index = self.recorder.creature_index
        entries = self.recorder.header[self.track.key]
        names = self.recorder.header["creatures"]
        keys = np.asarray(frame.keys, dtype=np.int64).reshape(-1)
        owners = [index[int(e)] for e in np.asarray(frame.creatures)[new].tolist()]
        orders = np.asarray(frame.order)[new].tolist()
        first = len(self.positions)
        added = []
        for k in sorted(range(len(new)), key=lambda k: (owners[k], orders[k])):
            i, creature = int(new[k]), owners[k]
            number = self._numbers.get(creature, 0)
            self._numbers[creature] = number + 1
            name = f"{names[creature]['name']}/{self.track.folder}/{self.track.item}{number}"
            radius = frame.radii[i]  # as given (a numpy number as the Python one)
            radius = radius.item() if isinstance(radius, np.generic) else radius
            entries.append({"name": name, "creature": creature, "radius": radius})
            self.positions.append(np.asarray(frame.positions[i], dtype=np.float64))
            added.append(keys[i])
        every = np.concatenate([self._keys, np.asarray(added, dtype=np.int64)])
        columns = np.concatenate([self._columns, np.arange(first, len(self.positions))])
        order = np.argsort(every, kind="stable")
        self._keys, self._columns = every[order], columns[order]

    def arrays(self, frames: int) -> dict[str, np.ndarray]:
        count = len(self.positions)
        live = np.zeros((frames, count), np.bool_)
        for frame, alive in enumerate(self.alive[:frames]):
            live[frame, alive] = True
        where, shown = self.track.arrays
        return {where: np.array(self.positions, np.float32).reshape(count, 3), shown: live}


_NONE = np.zeros(0, dtype=np.int64)


def _found(known: np.ndarray, keys: np.ndarray) -> np.ndarray:
    """Which of `keys` are in `known` (sorted), as a bool array."""
    at = np.minimum(np.searchsorted(known, keys), max(len(known) - 1, 0))
    return known[at] == keys if len(known) else np.zeros(len(keys), dtype=np.bool_)


class CurvesTrack:
    """Records a curves track: the curves of every creature, each frame.

    Curves are columns by owner (the k-th curve of a creature is always one column), so
    when a creature comes or goes during the recording its curves join (holding their
    first shape before) or hold their last shape after; points per curve never change.
    A track first sampled after frame 0 (the first furred creature spawned then) holds
    its first shapes before.
    """

    def __init__(self, track: TakeTrack, sample: Any, recorder: Recorder):
        self.track, self.sample, self.recorder = track, sample, recorder
        self.points: list[np.ndarray] = []
        self.widths: list[np.ndarray] = []
        self.columns: list[np.ndarray] = []  # per frame: the column of each curve sampled
        self._column: dict[tuple[int, int], int] = {}  # (owner entity, k-th) -> column
        self._owners: list[int] = []  # per column: the take's creature index (-1: none)
        self.start = 0  # the take frame of the first sample
        self._last: tuple[np.ndarray, np.ndarray] | None = None  # owners and their columns

    def capture(self, world: World) -> None:
        frame: CurvesFrame | None = self.sample(world) if self.sample else None
        key = self.track.key
        if frame is None:
            if not self.points:
                return
            if not self.recorder.roster_changes:
                raise ValueError(f"take track {key!r} disappeared during the recording")
            shape = self.points[0].shape  # its creatures were despawned: every curve holds
            self.columns.append(np.zeros(0, dtype=np.int64))
            self.points.append(np.zeros((0, *shape[1:]), np.float32))
            self.widths.append(np.zeros((0, shape[1]), np.float32))
            return
        points = np.asarray(frame.points, dtype=np.float32)
        widths = np.broadcast_to(np.asarray(frame.widths, dtype=np.float32), points.shape[:2])
        if points.ndim != 3 or points.shape[2] != 3:
            raise ValueError(f"{key} points must be (curves, points, 3), got {points.shape}")
        if (self.points and points.shape[2:] != self.points[0].shape[2:]) or (
            self.points and points.shape[1] != self.points[0].shape[1]
        ):
            raise ValueError(f"{key} changed shape: {self.points[0].shape} -> {points.shape}")
        if not self.points:
            self.start = self.recorder.count
        owners = np.asarray(frame.creatures, dtype=np.int64)
        if self._last is None or not np.array_equal(owners, self._last[0]):
            self._last = (owners, self._columns_of(owners.tolist()))  # the curves changed
            self.recorder.header[key] = {"creatures": list(self._owners)}
        self.columns.append(self._last[1])
        self.points.append(points)
        self.widths.append(np.array(widths))

    def _columns_of(self, creatures: list[int]) -> np.ndarray:
        index, seen = self.recorder.creature_index, dict[int, int]()
        out = np.empty(len(creatures), dtype=np.int64)
        for i, entity in enumerate(creatures):
            k = seen[entity] = seen.get(entity, -1) + 1
            column = self._column.get((entity, k))
            if column is None:
                column = self._column[entity, k] = len(self._owners)
                self._owners.append(index.get(entity, -1))
            out[i] = column
        return out

    def arrays(self, frames: int) -> dict[str, np.ndarray]:
        if not self.points:
            return {}
        first, second = self.track.arrays
        count, start = len(self._owners), self.start
        sampled = range(max(0, min(frames - start, len(self.columns))))
        if start == 0 and all(
            len(self.columns[s]) == count and (self.columns[s] == np.arange(count)).all()
            for s in sampled
        ):
            return {first: np.stack(self.points[:frames]), second: np.stack(self.widths[:frames])}
        size = self.points[0].shape[1]
        points = np.empty((frames, count, size, 3), np.float32)
        widths = np.empty((frames, count, size), np.float32)
        seen = np.zeros(count, dtype=bool)  # before a curve's first sample: its first shape
        for s in range(len(self.columns)):
            fresh = ~seen[self.columns[s]]
            columns = self.columns[s][fresh]
            points[0, columns], widths[0, columns] = self.points[s][fresh], self.widths[s][fresh]
            seen[columns] = True
        for f in range(frames):
            if f:  # curves not sampled now hold their last shape
                points[f], widths[f] = points[f - 1], widths[f - 1]
            if f - start in sampled:
                s = f - start
                points[f, self.columns[s]] = self.points[s]
                widths[f, self.columns[s]] = self.widths[s]
        return {first: points, second: widths}
