"""Recording a take's tracks frame by frame (`export.recording.TakeRecorder` makes one
per track a plugin adds, `TakeTracks`): points tracks (locators that appear and stay
where they first appeared, live while sampled) and curves tracks (polylines posed every
frame). Each writes its part of the take's header and its two arrays.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Protocol

import numpy as np

from ecs_tentacles.numeric.rows import ordinals

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
    def capacity(self) -> int: ...  # frames the recorder has room for now

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

    def arrays(self, frames: int, copy: bool = True) -> dict[str, np.ndarray]:
        """The track's arrays for the first `frames` frames (new arrays either way)."""
        count = len(self.positions)
        live = np.zeros((frames, count), np.bool_)
        for frame, alive in enumerate(self.alive[:frames]):
            live[frame, alive] = True
        where, shown = self.track.arrays
        return {where: np.array(self.positions, np.float32).reshape(count, 3), shown: live}


_NONE = np.zeros(0, dtype=np.int64)
_PAIR = 2**32  # an owner entity and its k-th curve as one number: entity * _PAIR + k


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

    Frames go into preallocated (frames, columns, points) arrays: a frame whose curves
    are every column in order is one copy of the sample (which may be a view of the
    plugin's buffers); after a creature came or went, one copy of the frame before and
    one scatter. Columns are mapped to curves again only when the owners change.
    """

    def __init__(self, track: TakeTrack, sample: Any, recorder: Recorder):
        self.track, self.sample, self.recorder = track, sample, recorder
        self._points: np.ndarray | None = None  # (capacity, columns, points, 3) float32
        self._widths = np.zeros((0, 0, 0), np.float32)  # (capacity, columns, points)
        self._pairs = np.zeros(0, dtype=np.int64)  # every (owner entity, k-th) seen, sorted ...
        self._pair_columns = np.zeros(0, dtype=np.int64)  # ... and its column
        self._owners: list[int] = []  # per column: the take's creature index (-1: none)
        self.start = 0  # the take frame of the first sample
        self._first_shape: tuple[int, ...] = ()  # of the first sample
        # owners at the last change, their columns, and whether those are every column
        self._last: tuple[np.ndarray, np.ndarray, bool] | None = None
        self._offset = 0  # the frame of row 0 (frames before were handed on: `flush`)
        self._handed: tuple[np.ndarray, np.ndarray] | None = None  # the last frame handed on

    def capture(self, world: World) -> None:
        frame: CurvesFrame | None = self.sample(world) if self.sample else None
        key, f = self.track.key, self.recorder.count
        r = f - self._offset  # the row of frame f (frames before were handed on: `flush`)
        if frame is None:
            if self._points is None:
                return
            if not self.recorder.roster_changes:
                raise ValueError(f"take track {key!r} disappeared during the recording")
            self._room(r)  # its creatures were despawned: every curve holds
            self._hold(r)
            return
        points = np.asarray(frame.points, dtype=np.float32)
        widths = np.broadcast_to(np.asarray(frame.widths, dtype=np.float32), points.shape[:2])
        if points.ndim != 3 or points.shape[2] != 3:
            raise ValueError(f"{key} points must be (curves, points, 3), got {points.shape}")
        if self._points is not None and points.shape[1] != self._first_shape[1]:
            raise ValueError(f"{key} changed shape: {self._first_shape} -> {points.shape}")
        owners = np.asarray(frame.creatures, dtype=np.int64)
        known = len(self._owners)
        if self._last is None or not np.array_equal(owners, self._last[0]):
            columns = self._columns_of(owners)  # the curves changed
            whole = len(columns) == len(self._owners) and bool(
                np.array_equal(columns, np.arange(len(columns)))
            )
            self._last = (owners, columns, whole)
            self.recorder.header[key] = {"creatures": list(self._owners)}
        _, columns, whole = self._last
        if self._points is None:
            self.start, self._first_shape = f, points.shape
        self._room(r)
        assert self._points is not None
        if len(self._owners) > known:  # new curves: their first shape up to now
            new = np.flatnonzero(columns >= known)
            self._points[: r + 1, columns[new]] = points[new]
            self._widths[: r + 1, columns[new]] = widths[new]
        if whole:
            self._points[r], self._widths[r] = points, widths
        else:  # curves not sampled now hold their last shape
            self._hold(r)
            self._points[r, columns], self._widths[r, columns] = points, widths

    def _hold(self, r: int) -> None:
        """Row `r` holds the frame before's curves (handed on already when `r` is 0)."""
        assert self._points is not None
        if r:
            self._points[r], self._widths[r] = self._points[r - 1], self._widths[r - 1]
        elif self._handed is not None:
            points, widths = self._handed
            self._points[0, : points.shape[0]], self._widths[0, : widths.shape[0]] = points, widths

    def flush(self, upto: int) -> dict[str, np.ndarray] | None:
        """Hand on frames up to `upto` (exclusive) and forget them: their arrays (None
        before the first sample). A streamed take stores them in chunks; frames before a
        curve first appeared are filled by the reader with its first shape."""
        if self._points is None:
            return None
        rows = upto - self._offset
        first, second = self.track.arrays
        out = {first: self._points[:rows].copy(), second: self._widths[:rows].copy()}
        if rows:
            self._handed = (out[first][-1], out[second][-1])
        self._offset = upto
        return out

    def _room(self, r: int) -> None:
        """Make the arrays hold row `r` and every column."""
        count, size = len(self._owners), self._first_shape[1]
        if self._points is None:
            frames = max(self.recorder.capacity, r + 1)
            self._points = np.empty((frames, count, size, 3), np.float32)
            self._widths = np.empty((frames, count, size), np.float32)
            return
        frames = len(self._points)
        if r >= frames:
            frames = max(2 * frames, r + 1)
        if frames > len(self._points) or count > self._points.shape[1]:
            self._points = _resized(self._points, frames, count)
            self._widths = _resized(self._widths, frames, count)

    def _columns_of(self, creatures: np.ndarray) -> np.ndarray:
        """Each curve's column: the k-th curve of a creature keeps its column, curves not
        seen before take the next ones in order (array work; Python only per new owner)."""
        pairs = creatures * _PAIR + ordinals(creatures)  # (entity, k-th) as one number
        new = np.flatnonzero(~_found(self._pairs, pairs))
        if len(new):
            index = self.recorder.creature_index
            entities, which = np.unique(creatures[new], return_inverse=True)
            owners = np.array([index.get(e, -1) for e in entities.tolist()], dtype=np.int64)
            first = len(self._owners)
            self._owners += owners[which].tolist()
            every = np.concatenate([self._pairs, pairs[new]])
            columns = np.concatenate([self._pair_columns, np.arange(first, len(self._owners))])
            order = np.argsort(every, kind="stable")
            self._pairs, self._pair_columns = every[order], columns[order]
        found: np.ndarray = self._pair_columns[np.searchsorted(self._pairs, pairs)]
        return found

    def arrays(self, frames: int, copy: bool = True) -> dict[str, np.ndarray]:
        """The track's arrays for the first `frames` frames (`copy=False`: views of the
        recorder's own, for a take that ends the recording)."""
        if self._points is None:
            return {}
        first, second = self.track.arrays
        rows = frames - self._offset
        points, widths = self._points[:rows], self._widths[:rows]
        if copy:
            points, widths = points.copy(), widths.copy()
        return {first: points, second: widths}


def _resized(array: np.ndarray, frames: int, columns: int) -> np.ndarray:
    """`array` (frames, columns, ...) in a new one of `frames` frames and `columns`
    columns, what it held kept in place (the rest to be written)."""
    grown = np.empty((frames, columns, *array.shape[2:]), array.dtype)
    grown[: len(array), : array.shape[1]] = array
    return grown
