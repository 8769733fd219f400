"""The World: one esper context, the stores, the physics backend and the schedule.

    world = World.from_scene("assets/scenes/octopus.json")
    world.step(60)                       # one simulated second at 60 fps
    octo = world.creature("octopus")
    print(world.component(octo, Transform).pos)

Each World owns its own esper context, so several worlds (tests, parallel bakes)
live side by side; every World method switches to its context first.
"""

from __future__ import annotations

import gc
import os
import pathlib
import uuid
from collections.abc import Callable, Collection, Iterator, Mapping
from typing import TYPE_CHECKING, Any, TypeVar

import esper
import numpy as np

from ecs_tentacles import stops
from ecs_tentacles.components import Creature
from ecs_tentacles.events import Events
from ecs_tentacles.options import Focus, WorldOptions
from ecs_tentacles.physics.backend import PhysicsBackend
from ecs_tentacles.plugin import Plugin, calling
from ecs_tentacles.registry import App, Registries, RegistryLike
from ecs_tentacles.scene.layouts import Layouts
from ecs_tentacles.schedule import Schedule
from ecs_tentacles.settings import Settings as Settings  # re-exported: old imports work
from ecs_tentacles.store import (
    ArrayStore,
    CreatureStore,
    MotorStore,
    SuckerStore,
    TentacleStore,
    TransformStore,
)
from ecs_tentacles.system import System, SystemFailure

if TYPE_CHECKING:
    from typing_extensions import Unpack  # (typing's own from Python 3.12)

    from ecs_tentacles.host import Placement
    from ecs_tentacles.physics.lod import LevelOfDetail
    from ecs_tentacles.scene.spec import CreatureSpec
    from ecs_tentacles.snapshot import Snapshot

__all__ = ["MissingResource", "Settings", "World"]  # Settings lives in ecs_tentacles.settings

C = TypeVar("C")
R = TypeVar("R")
G = TypeVar("G", bound=RegistryLike)


class World:
    """Entities, their stores, the physics and the systems that run each frame."""

    def __init__(self, settings: Settings | None = None, *, seed: int = 0, name: str = "world"):
        self.name = name
        self.settings = settings or Settings()
        self.seed = seed
        self.rng = np.random.default_rng(seed)
        self.context = f"ecs_tentacles:{name}:{uuid.uuid4().hex}"
        esper.switch_world(self.context)
        self.froze_build = False  # a crowd's build froze its objects (`close` unfreezes)
        self.transforms = TransformStore()
        self.motors = MotorStore()
        self.suckers = SuckerStore()
        self.creatures = CreatureStore()
        self.tentacles = TentacleStore()
        # every store by name: the core's, then the plugins' ("fur.guides"); systems
        # declare "<store>.<field>" against these names
        self.stores: dict[str, ArrayStore] = {
            "transforms": self.transforms,
            "motors": self.motors,
            "suckers": self.suckers,
            "creatures": self.creatures,
            "tentacles": self.tentacles,
        }
        self.plugins: list[Plugin] = []
        self._resources: dict[type, Any] = {}  # plugins' stores and APIs, by type
        self.registries = Registries()  # what the layers call, filled in plugins' build(app)
        self.schedule = Schedule()
        self.events = Events()
        self._physics: PhysicsBackend | None = None
        self.options = WorldOptions(seed=seed)  # the run's choices (`from_scene` sets them)
        self.scene: dict[str, Any] | None = None  # the validated scene, defaults filled in
        self.scene_dir: pathlib.Path | None = None  # its folder: plugin files are found there
        # every creature's entry (validated, defaults in) by entity: the scene's and spawns'
        self.creature_specs: dict[int, CreatureSpec] = {}  # by entity, spawned ones too
        # each creature entry's layout while the world is built (`scene.layouts`)
        self.layouts = Layouts()
        # names no new creature may take although no creature has them now: a take being
        # recorded names each creature once (`TakeRecorder` keeps its creatures' here)
        self.kept_names: set[str] = set()
        self.frame = 0

    # -- construction ------------------------------------------------------------------
    @classmethod
    def from_scene(
        cls,
        source: str | os.PathLike[str] | dict[str, object],
        options: WorldOptions | None = None,
        *,
        seed: int | None = None,
        allow_systems: bool | None = None,
        threads: int | None = None,
        only: Collection[int] | None = None,
        plugins: Mapping[str, object] | None = None,
        scene_dir: str | os.PathLike[str] | None = None,
        lod: bool | None = None,
        focus: Focus | None = None,
    ) -> World:
        """Build a world from a scene file, bundled scene name or dict.

        Validates, builds the entities (the creature bodies, then each plugin's build
        hooks), compiles the physics, schedules the systems of every plugin on
        (`ecs_tentacles.creatures.loading`).

        Raises `SceneError` (one line per problem) before anything is built. `options`
        (`ecs_tentacles.options.WorldOptions`) are the run's choices over the scene's:
        seed, code the scene may import (`allow_systems`), threads, level of detail and
        its focus, plugins turned on or off, the creatures to build (`only`). Each
        keyword given sets that field over `options` (`World.from_scene(path,
        threads=1)`); None leaves it.
        """
        from ecs_tentacles.creatures.loading import WorldClass, load_world

        given = {
            "seed": seed,
            "allow_systems": allow_systems,
            "threads": threads,
            "only": only,
            "plugins": plugins,
            "scene_dir": scene_dir,
            "lod": lod,
            "focus": focus,
        }
        options = (options or WorldOptions()).but(
            **{name: value for name, value in given.items() if value is not None}
        )
        world_class: WorldClass[World] = cls
        return load_world(world_class, source, options)

    # -- creatures that come and go ------------------------------------------------------
    def spawn(self, creature: Mapping[str, object], **placement: Unpack[Placement]) -> int:
        """Build one creature (a scene-style entry) into this running world; its entity.

        Validated as a scene entry (`SpawnError`, one line per problem); a taken name
        gets a suffix (`octo_2`). `placement` (`ecs_tentacles.host.Placement`): `position`
        and `heading_deg` over the entry's; overlapping a creature or an obstacle is
        refused, or with `on_overlap="move"` moved to the nearest free spot. Other
        creatures step on exactly as if it never came. Emits `creature_spawned`
        (`ecs_tentacles.creatures.spawning`).
        """
        from ecs_tentacles.creatures.spawning import spawn

        return spawn(self, creature, **placement)

    def despawn(self, creature: int) -> None:
        """Remove creature `creature` (an entity) and all it owns; others step on as if it
        had stayed away from them. Emits `creature_despawned`
        (`ecs_tentacles.creatures.spawning`)."""
        from ecs_tentacles.creatures.spawning import despawn

        despawn(self, creature)

    def build_physics(self, threads: int | None = None) -> PhysicsBackend:
        """Compile the physics groups from the current entities and sync the Transform store.

        `threads` steps the groups on that many threads (default: one per core).
        """
        self.activate()
        if self._physics is not None:
            self._physics.close()
        self._physics = PhysicsBackend(self, threads)
        self._physics.sync(self.transforms)
        self._physics.health.previous = self.transforms.pos.copy()
        return self._physics

    @property
    def physics(self) -> PhysicsBackend:
        if self._physics is None:
            raise RuntimeError("this world has no physics yet: call world.build_physics()")
        return self._physics

    @property
    def lod(self) -> LevelOfDetail:
        """Level of detail (`ecs_tentacles.physics.lod`): `world.lod.promote(creature)`."""
        return self.physics.lod

    def add_plugin(self, plugin: Plugin) -> Plugin:
        """Turn a plugin on in a built world: its resources, then its systems (set up).

        Build hooks are not run (the creatures exist already): plugins that build data
        per creature are turned on in the scene (`plugins`) instead.
        """
        from ecs_tentacles.creatures.loading import owned_systems

        self.adopt(plugin)
        self.add_systems(*owned_systems(plugin))
        return plugin

    def adopt(self, plugin: Plugin) -> None:
        """Add a plugin's resources and stores, not its systems (scene loading's first step)."""
        if any(p.key == plugin.key for p in self.plugins):
            raise ValueError(f"plugin {plugin.key!r} is already on in this world")
        with calling(plugin, "resources"):
            made = plugin.resources(self)
        objects = list(made.values() if isinstance(made, Mapping) else made)
        for obj in objects:
            if type(obj) in self._resources:
                raise ValueError(
                    f"plugin {plugin.key!r}: this world has a {type(obj).__name__} already"
                )
        self.plugins.append(plugin)
        for obj in objects:
            self._resources[type(obj)] = obj
        for name, store in plugin.stores(self).items():
            if name in self.stores or name.partition(".")[0] != plugin.name:
                raise ValueError(
                    f"plugin {plugin.key!r}: store name {name!r} is taken or does not start"
                    f" with {plugin.name!r}"
                )
            self.stores[name] = store
        with calling(plugin, "build"):
            plugin.build(App(self.registries, plugin, self))

    def registry(self, kind: type[G]) -> G:
        """The world's `kind` registry (`ecs_tentacles.registry`): the entries plugins added
        in `build(app)`, in plugin order."""
        return self.registries.get(kind)

    def plugin(self, key: str) -> Plugin:
        """The plugin on as `key`."""
        for plugin in self.plugins:
            if plugin.key == key:
                return plugin
        on = ", ".join(p.key for p in self.plugins) or "none"
        raise KeyError(f"no plugin {key!r} is on in this world (on: {on})")

    # -- resources ----------------------------------------------------------------------
    def resource(self, kind: type[R]) -> R:
        """The plugins' resource of type `kind` (`world.resource(GoalBook)`), as Bevy's `Res<T>`.

        Raises `MissingResource` naming the plugin that provides it when it is not on.
        """
        found = self.get_resource(kind)
        if found is None:
            raise MissingResource(kind, [p.key for p in self.plugins])
        return found

    def get_resource(self, kind: type[R]) -> R | None:
        """The resource of type `kind`, or None when no plugin that is on provides one.

        A class re-imported by hot reload (`ecs_tentacles.reload`) is a new type object:
        it finds the resource made from its old self (same module and name).
        """
        found = self._resources.get(kind)
        if found is None:
            name = (kind.__module__, kind.__qualname__)
            for made, obj in self._resources.items():
                if (made.__module__, made.__qualname__) == name:
                    same: R = obj  # the same class, imported again
                    return same
        return found

    def replace_resource(self, obj: object) -> None:
        """Put `obj` in place of the resource of its type a plugin provided (the terrain's
        editor swaps the `Ground` this way); KeyError if there is none to replace."""
        kind = type(obj)
        if kind not in self._resources:
            raise KeyError(f"this world has no {kind.__name__} to replace")
        self._resources[kind] = obj

    def has_resource(self, kind: type) -> bool:
        """Whether a plugin that is on provides a resource of type `kind`."""
        return self.get_resource(kind) is not None

    @property
    def resources(self) -> tuple[object, ...]:
        """Every plugin resource of this world."""
        return tuple(self._resources.values())

    def add_system(self, system: System) -> System:
        """Schedule `system` at the place it declares and call its `setup`."""
        self.add_systems(system)
        return system

    def add_systems(self, *systems: System) -> None:
        """Schedule several systems at once (they may name each other), then set them up.

        A `setup` that raises is a `SystemFailure` (at the current frame).
        """
        self.schedule.add(*systems)
        for system in systems:
            try:
                system.setup(self)
            except (Exception, SystemExit) as error:  # name the system, as process() does
                label = self.schedule.label(system)
                raise SystemFailure(system, label, self.frame, error) from error

    # -- running -----------------------------------------------------------------------
    def step(
        self, frames: int = 1, *, on_failure: Callable[[SystemFailure], None] | None = None
    ) -> None:
        """Run `frames` fixed-duration frames: every system in schedule order.

        An exception inside a system is raised as `SystemFailure` (naming the system,
        its plugin and the frame; the original is its `__cause__`); the frame counter
        stays at the failed frame. With `on_failure`, it is called with the failure
        instead and the frame goes on with the next system (the sandbox disables the
        failed one there and keeps running).

        Under the command line a Ctrl-C or SIGTERM arriving meanwhile is raised before
        the next frame, not inside this one (a second one at once: `ecs_tentacles.stops`).
        """
        self.activate()
        dt = self.settings.dt
        with stops.deferred():
            self._frames(frames, dt, on_failure)

    def _frames(
        self, frames: int, dt: float, on_failure: Callable[[SystemFailure], None] | None
    ) -> None:
        for _ in range(frames):
            stops.check()
            for system in self.schedule:  # a disable() now does not change this frame's list
                try:
                    system.process(self, dt)
                except SystemFailure as named:  # a substep hook, named by the physics system
                    if on_failure is None:
                        raise
                    on_failure(named)
                except (Exception, SystemExit) as error:  # name system and frame; cause kept
                    failure = SystemFailure(system, self.schedule.label(system), self.frame, error)
                    if on_failure is None:
                        raise failure from error
                    failure.__cause__ = error
                    on_failure(failure)
            self.frame += 1

    def snapshot(self) -> Snapshot:
        """The whole simulation state, to `restore` later (`ecs_tentacles.snapshot`)."""
        from ecs_tentacles import snapshot

        self.activate()
        return snapshot.take(self)

    def restore(self, state: Snapshot) -> None:
        """Go back to a `snapshot()` of this world; stepping on repeats exactly."""
        from ecs_tentacles import snapshot

        self.activate()
        with self.events.held():  # handlers run after: a restore is whole or nothing
            snapshot.restore(self, state)

    @property
    def time(self) -> float:
        """Simulated seconds since the start."""
        return self.frame * self.settings.dt

    # -- entities ----------------------------------------------------------------------
    def activate(self) -> None:
        """Make this world's esper context the current one."""
        if esper.current_world != self.context:
            esper.switch_world(self.context)

    def create_entity(self, *components: object) -> int:
        self.activate()
        return esper.create_entity(*components)

    def add_component(self, entity: int, component: object) -> None:
        """Give `entity` a component (at build time: it invalidates esper's query cache)."""
        self.activate()
        esper.add_component(entity, component)

    def component(self, entity: int, kind: type[C]) -> C:
        """The `kind` component of `entity` (KeyError if it has none)."""
        self.activate()
        return esper.component_for_entity(entity, kind)

    def try_component(self, entity: int, kind: type[C]) -> C | None:
        self.activate()
        return esper.try_component(entity, kind)

    def query(self, *kinds: type) -> Iterator[tuple[int, Any]]:
        """(entity, component) or (entity, (components...)) for entities having all `kinds`."""
        self.activate()
        if len(kinds) == 1:
            return iter(esper.get_component(kinds[0]))
        return iter(esper.get_components(*kinds))

    def creature_name(self, entity: int) -> str:
        """The name of creature `entity`."""
        return self.component(entity, Creature).name

    def creature(self, name: str) -> int:
        """The entity of the creature called `name`."""
        for entity, creature in self.query(Creature):
            if creature.name == name:
                return entity
        names = ", ".join(c.name for _, c in self.query(Creature))
        raise KeyError(f"no creature named {name!r}; this world has: {names}")

    def close(self) -> None:
        """Stop the physics threads and delete this world's esper context; the objects
        a crowd's build froze are the collector's again (`loading.FROZEN_CROWD`)."""
        if self.froze_build:
            self.froze_build = False
            gc.unfreeze()
        if self._physics is not None:
            self._physics.close()
        if esper.current_world == self.context:
            esper.switch_world("default")
        if self.context in esper.list_worlds():
            esper.delete_world(self.context)

    def __enter__(self) -> World:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


class MissingResource(LookupError):
    """`world.resource(T)` found no T: the plugin that provides it is off."""

    def __init__(self, kind: type, on: list[str]):
        provider = getattr(kind, "provided_by", "")
        which = f"the {provider!r} plugin provides it" if provider else "no plugin on provides it"
        super().__init__(
            f"this world has no {kind.__name__}: {which} (plugins on: {', '.join(on) or 'none'})"
        )
