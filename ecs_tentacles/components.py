"""Components: plain dataclasses attached to esper entities.

Numbers that systems touch every frame live in stores (`ecs_tentacles.store`); the
components that expose them (`Transform`, `Motor`, `Sucker`) hold their store and
row, and each field reads as a writable numpy view (vectors) or a float (scalars):

    world.component(link, Transform).pos     # (3,) writable view into the TransformStore
    world.component(link, Motor).strength = 8.0  # reaches the servo on the next step

Structural components (`Creature`, `Tentacle`, `Link`) are plain data fixed at
construction; features define their own (`ecs_tentacles.locomotion.components`).
Components are never added or removed per frame.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from ecs_tentacles.store import ArrayStore, MotorStore, SuckerStore, TransformStore


class RowField:
    """A component attribute that reads and writes one row of a store field."""

    def __set_name__(self, owner: type, name: str) -> None:
        self.name = name

    def __get__(self, component: Any, owner: type | None = None) -> Any:
        if component is None:
            return self
        value = getattr(component.store, self.name)[component.row]
        return value.item() if value.ndim == 0 else value

    def __set__(self, component: Any, value: Any) -> None:
        getattr(component.store, self.name)[component.row] = value


@dataclass(eq=False, slots=True)
class RowComponent:
    """Base of components whose numeric fields (`RowField`s) live in one store row.

    Made as `Transform(store, row)`; it keeps the row's handle (`ArrayStore.row_of`), so
    `row` stays right when a despawn moves the rows after a removed creature's up.
    """

    store: ArrayStore
    handle: int  # given a row when made; kept as that row's handle

    def __post_init__(self) -> None:
        self.handle = self.store.handle_at(self.handle)

    @property
    def row(self) -> int:
        """The store row this component's numbers are in now."""
        row = self.store.row_of(self.handle)
        if row < 0:
            raise LookupError(f"this {type(self).__name__}'s creature was despawned")
        return row

    def __repr__(self) -> str:
        names = [
            n for k in type(self).__mro__ for n, v in vars(k).items() if isinstance(v, RowField)
        ]
        shown = ", ".join(f"{n}={getattr(self, n)!r}" for n in names)
        return f"{type(self).__name__}(row={self.row}, {shown})"


@dataclass(eq=False, repr=False, slots=True)
class Transform(RowComponent):
    """World pose of a body: `pos` (3,) metres, `quat` (4,) unit quaternion (w, x, y, z)."""

    store: TransformStore
    pos = RowField()
    quat = RowField()


@dataclass(eq=False, repr=False, slots=True)
class Motor(RowComponent):
    """A link's servo: `target` (curl, sweep, twist) radians, `strength` kp, `damping` kv."""

    store: MotorStore
    target = RowField()
    strength = RowField()
    damping = RowField()
    max_torque = RowField()


@dataclass(eq=False, repr=False, slots=True)
class Sucker(RowComponent):
    """A sucker under a link: `offset` in the link frame, `attached`, world `anchor`."""

    store: SuckerStore
    link: int
    link_row = RowField()
    offset = RowField()
    attached = RowField()
    anchor = RowField()


class _StoreRow:
    """A structural component's row in its store, kept as the row's handle (so a
    despawn that moves rows up never leaves it stale); -1 until `attach`."""

    if TYPE_CHECKING:  # the dataclasses below declare them
        store: ArrayStore | None
        handle: int

    def attach(self, store: ArrayStore, row: int) -> None:
        """This component's numbers are in row `row` of `store`."""
        self.store, self.handle = store, store.handle_at(row)

    @property
    def row(self) -> int:
        return -1 if self.store is None else self.store.row_of(self.handle)


@dataclass(eq=False, slots=True)
class Creature(_StoreRow):
    """A creature: its mantle (a cylinder along +z) and its tentacles, counter-clockwise.

    `row` is its CreatureStore row (-1 before it is built)."""

    name: str
    mantle_radius: float
    mantle_height: float
    mantle_density: float
    tentacles: list[int] = field(default_factory=list)
    store: ArrayStore | None = None
    handle: int = -1


@dataclass(eq=False, slots=True)
class Tentacle(_StoreRow):
    """Tentacle `index` of `creature`; its axis is +x rotated by `base_angle` about +z.

    `row` is its TentacleStore row (-1 before it is built)."""

    creature: int
    index: int
    base_angle: float
    links: list[int] = field(default_factory=list)
    suckers: list[int] = field(default_factory=list)
    store: ArrayStore | None = None
    handle: int = -1


@dataclass(eq=False, slots=True)
class Link:
    """Link `index` of `tentacle`: a capsule along its local +x, `scale` of the first link."""

    tentacle: int
    index: int
    length: float
    radius: float
    scale: float
    density: float
    joint_limit: float
    twist: bool
