"""Struct-of-arrays stores: the numbers behind components.

Each store owns one contiguous numpy array per field, with a row per entity of its
kind. Built-in systems do whole-array math on `store.<field>` (a view of the live
rows); components (`ecs_tentacles.components`) hold a store and a row and expose
the same fields as writable views, so scripts can write
`world.component(link, Motor).target`. Stores grow by doubling, which is why
components look their field up on every access instead of keeping an old view.
The store itself keeps each field's view of the live rows as a plain attribute, made
again whenever the arrays change and at the first read after the rows do: a frame reads
fields some hundred times, and a descriptor that sliced the array on each read cost 0.12
us a read.

Rows are removed when a creature is despawned (`ArrayStore.remove`): the rows after
them move up, so every row keeps its order (a tentacle's links stay contiguous). A
column that holds rows of another store says so (`Field(refers="transforms")`) and is
renumbered with it; a store whose rows line up with another's (`lines_up_with`) loses
the same rows. Components keep a *handle* to their row, which never changes, so a
component made before a removal still finds its numbers after it.
"""

from __future__ import annotations

from typing import ClassVar, overload

import numpy as np
from numpy.typing import DTypeLike

HANDLE = "__handle__"  # the key of the rows' handles among a store's arrays


class Field:
    """A column of an `ArrayStore`: per-row shape, dtype and the value new rows get."""

    def __init__(
        self,
        shape: tuple[int, ...] = (),
        dtype: DTypeLike = np.float64,
        default: float | tuple[float, ...] = 0,
        refers: str | None = None,
    ):
        self.shape = shape
        self.dtype = np.dtype(dtype)
        self.default = default
        self.refers = refers  # a store name ("transforms"): these are its rows (-1: none)
        self.name = ""

    def __set_name__(self, owner: type, name: str) -> None:
        self.name = name

    @overload
    def __get__(self, store: None, owner: type | None = None) -> Field: ...
    @overload
    def __get__(self, store: ArrayStore, owner: type | None = None) -> np.ndarray: ...
    def __get__(self, store: ArrayStore | None, owner: type | None = None) -> Field | np.ndarray:
        # reached only while the store holds no view of this field: the view kept in the
        # instance's attributes is found first (no `__set__` here). One is made here,
        # and kept unless the store keeps none (`ArrayStore.cache_views`)
        if store is None:
            return self
        view = store._arrays[self.name][: store.count]
        if store.__dict__.get("cache_views", True):
            store.__dict__[self.name] = view
        return view


def without_rows(
    array: np.ndarray, new: np.ndarray, removed: np.ndarray | None = None
) -> np.ndarray:
    """`array` (a row per old row) without the rows that `new` (old row -> new row, -1
    removed) drops, the rows after them moved up in place: no new buffer (a despawn in a
    big crowd moves megabytes). `removed` (the dropped rows, sorted) if known. Returns
    the view of the rows left; `array` itself is changed."""
    rows = np.flatnonzero(new < 0) if removed is None else removed
    if not len(rows):
        return array
    first, last, count = int(rows[0]), int(rows[-1]) + 1, len(new)
    if last - first == len(rows):  # one run (a creature's rows): move the tail up
        array[first : count - len(rows)] = array[last:count]
    else:
        kept = array[:count][new >= 0]
        array[: len(kept)] = kept
    return array[: count - len(rows)]


class ArrayStore:
    """Rows of numbers for one kind of entity; subclasses declare `Field`s."""

    _declared_fields: tuple[Field, ...]  # `fields()`, set on each class at its first call
    _referring: dict[str, list[Field]]  # `referring()`, likewise
    # the store (by name in `world.stores`) whose rows this one's line up with, row for
    # row: it loses the same rows when a creature is despawned
    lines_up_with: ClassVar[str | None] = None

    def __init__(self, capacity: int = 16):
        self.count = 0
        self._arrays: dict[str, np.ndarray] = {
            f.name: np.empty((capacity, *f.shape), dtype=f.dtype) for f in self.fields()
        }
        # every row's handle (not a field: systems never see it), kept with the rows
        self._arrays[HANDLE] = np.empty(capacity, dtype=np.int64)
        self._row_of_handle = np.full(capacity, -1, dtype=np.int64)
        self._handles = 0  # handles issued
        # each field's view of the live rows kept as an attribute (False: every read
        # slices `_arrays` again, for a test that watches which columns are read)
        self.cache_views = True

    def _views(self) -> None:
        """Keep each field's view of the live rows as an instance attribute (after the
        arrays changed), or drop the kept views when `cache_views` is off."""
        names = [f.name for f in self.fields()]
        if self.__dict__.get("cache_views", True):
            arrays, count = self._arrays, self.count
            self.__dict__.update({name: dict.__getitem__(arrays, name)[:count] for name in names})
        else:
            self._drop_views()

    def _drop_views(self) -> None:
        """Forget the kept views (the rows changed): each is made again at its next read
        (`Field.__get__`). Building a crowd adds rows a creature at a time, 10,000
        creatures some million times: making every view again at each took 3 s."""
        state = self.__dict__
        for field in self.fields():
            state.pop(field.name, None)

    def __setattr__(self, name: str, value: object) -> None:
        """`store.field = values` writes into the live rows (the field's view is kept);
        `count`, `_arrays` and `cache_views` make the views again."""
        if isinstance(getattr(type(self), name, None), Field):
            view = self.__dict__.get(name)  # None while views are not kept
            if view is None:
                view = self._arrays[name][: self.count]
            view[...] = value
            return
        object.__setattr__(self, name, value)
        if name == "count":
            self._drop_views()
        elif name in ("_arrays", "cache_views") and "cache_views" in self.__dict__:
            self._views()

    def __getstate__(self) -> dict[str, object]:
        """Without the views: a copy makes its own of its own arrays."""
        fields = {f.name for f in self.fields()}
        return {k: v for k, v in self.__dict__.items() if k not in fields}

    def __setstate__(self, state: dict[str, object]) -> None:
        self.__dict__.update(state)
        self._views()

    @classmethod
    def fields(cls) -> list[Field]:
        """The declared fields, in declaration order (looked up once per class)."""
        known: tuple[Field, ...] | None = cls.__dict__.get("_declared_fields")
        if known is None:
            found: dict[str, Field] = {}
            for klass in reversed(cls.__mro__):
                for name, value in vars(klass).items():
                    if isinstance(value, Field):
                        found[name] = value
            known = tuple(found.values())
            cls._declared_fields = known  # on this class only: a subclass finds its own
        return list(known)

    @property
    def capacity(self) -> int:
        return len(next(iter(self._arrays.values()))) if self._arrays else 0

    def add(self, n: int = 1, **values: object) -> np.ndarray:
        """Append `n` rows (defaults, then `values` broadcast over them); return their indices."""
        if n < 0:
            raise ValueError(f"cannot add {n} rows")
        unknown = set(values) - set(self._arrays)
        if unknown:
            raise KeyError(f"{type(self).__name__} has no field(s) {sorted(unknown)}")
        self._reserve(self.count + n)
        start, stop = self.count, self.count + n
        for field in self.fields():
            self._arrays[field.name][start:stop] = values.get(field.name, field.default)
        # (the handles are set below)
        handles = np.arange(self._handles, self._handles + n)
        self._arrays[HANDLE][start:stop] = handles
        self._handles += n
        if self._handles > len(self._row_of_handle):
            grown = np.full(max(2 * len(self._row_of_handle), self._handles), -1, np.int64)
            grown[: len(self._row_of_handle)] = self._row_of_handle
            self._row_of_handle = grown
        self._row_of_handle[handles] = np.arange(start, stop)
        self.count = stop
        return np.arange(start, stop)

    def handle_at(self, row: int) -> int:
        """The handle of row `row`: it names that row whatever rows are removed before it."""
        if not 0 <= row < self.count:
            raise IndexError(f"{type(self).__name__} has no row {row} ({self.count} rows)")
        return int(self._arrays[HANDLE][row])

    def row_of(self, handle: int) -> int:
        """The row that handle `handle` names now, or -1 when it was removed."""
        return int(self._row_of_handle[handle])

    def remove(self, rows: np.ndarray) -> np.ndarray:
        """Remove `rows`; the rows after them move up. Returns every old row's new row
        (-1: removed), for renumbering what refers to this store (`renumber`)."""
        rows = np.unique(np.asarray(rows, dtype=np.int64))
        new = np.arange(self.count)
        if not len(rows):
            return new
        first, last = int(rows[0]), int(rows[-1]) + 1
        if last - first == len(rows):  # one run (a creature's rows)
            new[last:] -= len(rows)
        else:
            new -= np.searchsorted(rows, new)
        new[rows] = -1
        self._row_of_handle[self._arrays[HANDLE][rows]] = -1
        count = self.count
        for array in self._arrays.values():
            without_rows(array[:count], new, rows)
        self.count = count - len(rows)
        self._row_of_handle[self._arrays[HANDLE][: self.count]] = np.arange(self.count)
        return new

    @classmethod
    def referring(cls) -> dict[str, list[Field]]:
        """The fields that hold rows of another store, by that store's name."""
        known: dict[str, list[Field]] | None = cls.__dict__.get("_referring")
        if known is None:
            known = {}
            for field in cls.fields():
                if field.refers is not None:
                    known.setdefault(field.refers, []).append(field)
            cls._referring = known  # on this class only, as `fields`
        return known

    def renumber(self, store: str, new: np.ndarray) -> None:
        """Rows of `store` moved (`remove`'s answer): every field that refers to it follows."""
        fields = self.referring().get(store, ())
        if not fields:
            return
        to = np.append(new, -1)  # row -1 (none) stays -1
        for field in fields:
            values = self._arrays[field.name][: self.count]
            np.take(to, values, out=values)

    def _reserve(self, needed: int) -> None:
        capacity = self.capacity
        if needed <= capacity:
            return
        while capacity < needed:
            capacity = max(2 * capacity, 16)
        for name, array in self._arrays.items():  # (handles are in `_arrays` too)
            grown = np.empty((capacity, *array.shape[1:]), dtype=array.dtype)
            grown[: self.count] = array[: self.count]
            self._arrays[name] = grown
        self._views()

    def fit(self) -> None:
        """Free the spare room growth left: every array keeps just the live rows.

        Loading a scene calls it once every creature is built (rows added by doubling
        leave up to half of each array unused); the next `add` grows again.
        """
        if self.capacity == self.count:
            return
        for name, array in self._arrays.items():
            self._arrays[name] = array[: self.count].copy()
        self._views()

    def __len__(self) -> int:
        return self.count

    def copy_rows(self) -> tuple[int, dict[str, np.ndarray]]:
        """A copy of the live rows (for snapshots)."""
        return self.count, {f: a[: self.count].copy() for f, a in self._arrays.items()}

    def rows_problem(self, state: tuple[int, dict[str, np.ndarray]]) -> str | None:
        """Why `put_rows(state)` would not fit this store (one line), or None."""
        count, arrays = state
        if set(arrays) != set(self._arrays):
            return f"fields {sorted(arrays)}, here {sorted(self._arrays)}"
        if count > self.capacity:
            return f"{count} rows, here room for {self.capacity}"
        for name, values in arrays.items():
            here = self._arrays[name]
            if values.shape != (count, *here.shape[1:]) or values.dtype != here.dtype:
                shape = (count, *here.shape[1:])
                return f"{name}: {values.dtype}{values.shape}, here {here.dtype}{shape}"
        return None

    def put_rows(self, state: tuple[int, dict[str, np.ndarray]]) -> None:
        """Put back what `copy_rows` copied (the store must still have room for the rows)."""
        self.count, arrays = state
        for f, values in arrays.items():
            self._arrays[f][: self.count] = values
        self._row_of_handle[:] = -1
        handles = self._arrays[HANDLE][: self.count]
        if len(handles):
            self._handles = max(self._handles, int(handles.max()) + 1)
        if self._handles > len(self._row_of_handle):
            self._row_of_handle = np.full(self._handles, -1, np.int64)
        self._row_of_handle[handles] = np.arange(self.count)


class TransformStore(ArrayStore):
    """World poses of bodies (mantles and links): position and unit quaternion (w, x, y, z)."""

    pos = Field((3,))
    quat = Field((4,), default=(1.0, 0.0, 0.0, 0.0))


class MotorStore(ArrayStore):
    """Servo state per link: hinge targets (curl, sweep, twist) in radians and gains.

    The servo's kp is `strength * gain` and its kv `damping * gain`: `strength` and
    `damping` are the link's own (scene or script), `gain` is what locomotion writes
    each frame (action strength and writhing). `tentacle_row` and `arc` (where the
    link's centre lies along its tentacle, 0 at the base, 1 at the tip) let systems
    compute poses for every link at once.
    """

    target = Field((3,))
    strength = Field()
    damping = Field()
    max_torque = Field()
    gain = Field(default=1.0)
    tentacle_row = Field(dtype=np.int64, refers="tentacles")
    arc = Field()
    scale = Field(default=1.0)  # the link's construction scale (tapers strength)


class TentacleStore(ArrayStore):
    """Per tentacle: its body's layout, as arrays.

    Links of a tentacle are the contiguous motor rows `first_link .. first_link + links`.
    What a feature keeps per tentacle (locomotion's parameters and current action) lives
    in that feature's stores, row for row (`ecs_tentacles.locomotion.stores`).
    """

    creature_row = Field(dtype=np.int64, refers="creatures")
    base_angle = Field()
    first_link = Field(dtype=np.int64, refers="motors")
    links = Field(dtype=np.int64)
    base_row = Field(dtype=np.int64, refers="transforms")  # transform row of the first link
    tip_sucker = Field(dtype=np.int64, refers="suckers")  # sucker row on the tip link
    length = Field()
    joint_limit = Field()
    rest_pitch = Field()  # tilt that lays a tapering tentacle's underside on the ground


class CreatureStore(ArrayStore):
    """Per creature: its mantle row and size and its tentacle rows (features keep the rest)."""

    entity = Field(dtype=np.int64)
    mantle_row = Field(dtype=np.int64, refers="transforms")
    mantle_radius = Field()
    first_tentacle = Field(dtype=np.int64, refers="tentacles")
    tentacles = Field(dtype=np.int64)


class SuckerStore(ArrayStore):
    """Suckers: the link body row they sit on, offset in the link frame, attachment state."""

    link_row = Field(dtype=np.int64, refers="transforms")
    tentacle_row = Field(dtype=np.int64, refers="tentacles")
    entity = Field(dtype=np.int64)
    offset = Field((3,))
    attached = Field(dtype=np.bool_, default=False)
    anchor = Field((3,))
