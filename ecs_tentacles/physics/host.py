"""What the physics package needs of a world, and nothing more.

The physics (model building, batches, health check, sleep) is written against this
`typing.Protocol`, not against `ecs_tentacles.world.World`: the World satisfies it
structurally, and the physics package never imports the module that builds on it.
Systems and plugins see the wider `ecs_tentacles.host.Host`, which extends this one
(the stores, resources, schedule and plugins besides): `PhysicsHost` is the physics'
view of a world, `Host` everyone else's.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import TYPE_CHECKING, Any, Protocol, TypeVar

from ecs_tentacles.events import Events
from ecs_tentacles.settings import Settings
from ecs_tentacles.store import CreatureStore, SuckerStore, TentacleStore, TransformStore

if TYPE_CHECKING:
    from ecs_tentacles.registry import RegistryLike

C = TypeVar("C")
G = TypeVar("G", bound="RegistryLike")


class PhysicsHost(Protocol):
    """A world as the physics sees it: settings, clock, core stores, entities, events."""

    @property
    def settings(self) -> Settings: ...

    @property
    def frame(self) -> int:
        """Frames stepped so far."""

    @property
    def time(self) -> float:
        """Simulated seconds since the start."""

    @property
    def transforms(self) -> TransformStore: ...

    @property
    def suckers(self) -> SuckerStore: ...

    @property
    def creatures(self) -> CreatureStore: ...

    @property
    def tentacles(self) -> TentacleStore: ...

    @property
    def events(self) -> Events: ...

    def component(self, entity: int, kind: type[C]) -> C:
        """The `kind` component of `entity`."""

    def query(self, *kinds: type) -> Iterator[tuple[int, Any]]:
        """(entity, component(s)) for the entities having all `kinds`."""

    def creature_name(self, entity: int) -> str:
        """The name of creature `entity`."""

    def registry(self, kind: type[G]) -> G:
        """The world's `kind` registry (`ecs_tentacles.registry`)."""
