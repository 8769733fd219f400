"""Struct-of-arrays stores: the numbers behind components.

Each store owns one contiguous numpy array per field, with a row per entity of its
kind. Built-in systems do whole-array math on `store.<field>` (a view of the live
rows); components (`ecs_tentacles.components`) hold a store and a row and expose
the same fields as writable views, so scripts can write `link.transform.pos`.
Rows are never removed; stores grow by doubling, which is why components look their
field up on every access instead of keeping an old view.
"""

from __future__ import annotations

from typing import Any

import numpy as np


class Field:
    """A column of an `ArrayStore`: per-row shape, dtype and the value new rows get."""

    def __init__(self, shape: tuple[int, ...] = (), dtype: Any = np.float64, default: Any = 0):
        self.shape = shape
        self.dtype = np.dtype(dtype)
        self.default = default
        self.name = ""

    def __set_name__(self, owner: type, name: str) -> None:
        self.name = name

    def __get__(self, store: ArrayStore | None, owner: type | None = None) -> Any:
        if store is None:
            return self
        return store._arrays[self.name][: store.count]

    def __set__(self, store: ArrayStore, value: Any) -> None:
        store._arrays[self.name][: store.count] = value


class ArrayStore:
    """Rows of numbers for one kind of entity; subclasses declare `Field`s."""

    def __init__(self, capacity: int = 16):
        self.count = 0
        self._arrays: dict[str, np.ndarray] = {
            f.name: np.empty((capacity, *f.shape), dtype=f.dtype) for f in self.fields()
        }

    @classmethod
    def fields(cls) -> list[Field]:
        """The declared fields, in declaration order."""
        found: dict[str, Field] = {}
        for klass in reversed(cls.__mro__):
            for name, value in vars(klass).items():
                if isinstance(value, Field):
                    found[name] = value
        return list(found.values())

    @property
    def capacity(self) -> int:
        return len(next(iter(self._arrays.values()))) if self._arrays else 0

    def add(self, n: int = 1, **values: Any) -> np.ndarray:
        """Append `n` rows (defaults, then `values` broadcast over them); return their indices."""
        if n < 0:
            raise ValueError(f"cannot add {n} rows")
        unknown = set(values) - set(self._arrays)
        if unknown:
            raise KeyError(f"{type(self).__name__} has no field(s) {sorted(unknown)}")
        self._reserve(self.count + n)
        rows = np.arange(self.count, self.count + n)
        for field in self.fields():
            self._arrays[field.name][rows] = values.get(field.name, field.default)
        self.count += n
        return rows

    def _reserve(self, needed: int) -> None:
        capacity = self.capacity
        if needed <= capacity:
            return
        while capacity < needed:
            capacity = max(2 * capacity, 16)
        for name, array in self._arrays.items():
            grown = np.empty((capacity, *array.shape[1:]), dtype=array.dtype)
            grown[: self.count] = array[: self.count]
            self._arrays[name] = grown

    def __len__(self) -> int:
        return self.count


class TransformStore(ArrayStore):
    """World poses of bodies (mantles and links): position and unit quaternion (w, x, y, z)."""

    pos = Field((3,))
    quat = Field((4,), default=(1.0, 0.0, 0.0, 0.0))


class MotorStore(ArrayStore):
    """Servo state per link: hinge targets (curl, sweep, twist) in radians and gains."""

    target = Field((3,))
    strength = Field()
    damping = Field()
    max_torque = Field()


class SuckerStore(ArrayStore):
    """Suckers: the link body row they sit on, offset in the link frame, attachment state."""

    link_row = Field(dtype=np.int64)
    offset = Field((3,))
    attached = Field(dtype=np.bool_, default=False)
    anchor = Field((3,))
