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
from typing import Any

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


@dataclass(eq=False, slots=True)
class Creature:
    """A creature: its mantle (a cylinder along +z) and its tentacles, counter-clockwise."""

    name: str
    mantle_radius: float
    mantle_height: float
    mantle_density: float
    row: int = -1  # CreatureStore row
    tentacles: list[int] = field(default_factory=list)


@dataclass(eq=False, slots=True)
class Tentacle:
    """Tentacle `index` of `creature`; its axis is +x rotated by `base_angle` about +z."""

    creature: int
    index: int
    base_angle: float
    row: int = -1  # TentacleStore row
    links: list[int] = field(default_factory=list)
    suckers: list[int] = field(default_factory=list)


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
