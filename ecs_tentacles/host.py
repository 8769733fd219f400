"""`Host`: what systems and plugins may use of the world they run in.

`System.process/setup/substep`, the `Plugin` hooks, creature building and the scene
helpers take a `Host`, not the concrete `ecs_tentacles.world.World`, so nothing the
World imports has to import it back (no import circle, not even a type-only one).
`World` satisfies it structurally; a user system annotated `world: Host` (or left
unannotated) runs in any world.

    from ecs_tentacles.host import Host

    class Wobble(System):
        def process(self, world: Host, dt: float) -> None:
            world.motors.target[:, 0] += 0.1 * np.sin(world.time)

Reads and writes nothing itself.
"""

from __future__ import annotations

import pathlib
from collections.abc import Iterator, Mapping, Sequence
from typing import TYPE_CHECKING, Any, Literal, Protocol, TypedDict, TypeVar

from ecs_tentacles.physics.host import PhysicsHost

if TYPE_CHECKING:
    import numpy as np
    from typing_extensions import Unpack  # (typing's own from Python 3.12)

    from ecs_tentacles.physics.backend import PhysicsBackend
    from ecs_tentacles.scene.layouts import Layouts
    from ecs_tentacles.scene.spec import CreatureSpec
    from ecs_tentacles.store import ArrayStore, MotorStore, TentacleStore

C = TypeVar("C")
R = TypeVar("R")


class Placement(TypedDict, total=False):
    """Where a spawned creature goes (`World.spawn(entry, position=..., ...)`), over its
    entry's own `position` and `heading_deg`."""

    position: Sequence[float] | np.ndarray | None  # x, y (resting on the ground) or x, y, z
    heading_deg: float | None
    # "refuse": a creature or an obstacle in the way is a SpawnError; "move": the
    # nearest free spot is taken instead
    on_overlap: Literal["refuse", "move"]


PLACEMENT_KEYS = frozenset(Placement.__annotations__)


class Host(PhysicsHost, Protocol):
    """The world as a system or plugin sees it: what the physics sees (settings, clock,
    transforms, suckers, creatures, events, components; `PhysicsHost`) and the rest of
    the stores, the resources, the schedule, the plugins and entity creation."""

    @property
    def name(self) -> str: ...
    @property
    def seed(self) -> int: ...
    @property
    def rng(self) -> np.random.Generator: ...
    @property
    def scene(self) -> dict[str, Any] | None:
        """The validated scene, defaults filled in (None for a world built by hand)."""

    @property
    def scene_dir(self) -> pathlib.Path | None: ...
    @property
    def creature_specs(self) -> dict[int, CreatureSpec]:
        """Every creature's entry (validated, defaults in) by entity, spawned ones too."""

    @property
    def layouts(self) -> Layouts:
        """Each creature entry's layout, worked out once while the world is built (a
        plugin's `build_scene` reads them: `layouts.on(spec, ground)`); empty after."""

    @property
    def kept_names(self) -> set[str]:
        """Names no new creature may take (a recording's creatures, despawned ones too)."""

    # -- creatures that come and go (`ecs_tentacles.creatures.spawning`) ---------------
    def spawn(self, creature: Mapping[str, object], **placement: Unpack[Placement]) -> int:
        """Build one creature (a scene-style entry) into the running world; its entity
        (`World.spawn`)."""

    def despawn(self, creature: int) -> None: ...

    # -- the other core stores (every store by name in `stores`) ---------------------------
    @property
    def motors(self) -> MotorStore: ...
    @property
    def tentacles(self) -> TentacleStore: ...
    @property
    def stores(self) -> dict[str, ArrayStore]: ...

    @property
    def physics(self) -> PhysicsBackend: ...
    @property
    def schedule(self) -> SystemsView:
        """The frame's systems (`ecs_tentacles.schedule.Schedule`)."""

    @property
    def plugins(self) -> list[Any]:
        """The plugins on (`ecs_tentacles.plugin.Plugin`), in build order."""

    # -- plugins' resources, by type ------------------------------------------------------
    def resource(self, kind: type[R]) -> R: ...
    def get_resource(self, kind: type[R]) -> R | None: ...
    def has_resource(self, kind: type) -> bool: ...
    def replace_resource(self, obj: object) -> None: ...

    # -- entities ---------------------------------------------------------------------------
    def activate(self) -> None: ...
    def create_entity(self, *components: object) -> int: ...
    def add_component(self, entity: int, component: object) -> None: ...
    def try_component(self, entity: int, kind: type[C]) -> C | None: ...
    def creature(self, name: str) -> int: ...

    # -- state, between frames (not from a system: a frame is never cut in two) ---------
    # (a `ecs_tentacles.snapshot.Snapshot`: not named here, snapshot.py reads the Host)
    def snapshot(self) -> Any: ...
    def restore(self, state: Any) -> None: ...


class SystemsView(Protocol):
    """What systems and plugins use of the schedule (`ecs_tentacles.schedule.Schedule`):
    a system by name, whether one is scheduled, the substep hooks and a system's label.
    (Typed loosely, so this module needs neither the Schedule nor System.)"""

    def __contains__(self, name: object) -> bool: ...
    def __getitem__(self, name: str) -> Any: ...
    def __iter__(self) -> Iterator[Any]: ...
    def substep_systems(self) -> tuple[Any, ...]: ...
    def label(self, system: Any) -> str: ...
