"""Scene -> a running world: validate, import, build, compile physics, schedule.

`World.from_scene` delegates here; this module sits above everything it uses (scene
validation, plugins, creature building, the core systems) and imports no `World`:
the class to build is passed in (`WorldClass`), so world.py imports nothing that
imports it back.

Order: the scene is validated and its plugins imported (user code only with
`allow_systems`); the world is made from the scene's `physics` settings; each plugin's
resources and stores join it; every creature's body is built, then each plugin's
`build_creature` and `build_scene` hooks run; every store is cut to its rows
(`ArrayStore.fit`); the physics is compiled; the core
systems and every plugin's systems are scheduled and set up; each plugin's `ready`
hook sees the world before its first frame; a crowd's objects are then frozen
(`FROZEN_CROWD`). If a plugin's `systems()`, a system's `setup()` or a `ready` raises,
the half-built world is closed (its physics threads and esper context) before the
error goes on.
"""

from __future__ import annotations

import contextlib
import gc
import importlib
import os
import pathlib
from collections.abc import Collection, Iterator, Mapping
from dataclasses import replace
from typing import Protocol, TypeVar

from ecs_tentacles import stops
from ecs_tentacles.creatures.body import build_creature
from ecs_tentacles.ground import ground_of
from ecs_tentacles.host import Host
from ecs_tentacles.options import WorldOptions
from ecs_tentacles.physics.frame_systems import physics_systems
from ecs_tentacles.plugin import HookFailure, Plugin, SystemsPlugin, calling
from ecs_tentacles.scene.errors import SceneError
from ecs_tentacles.scene.layouts import Layouts
from ecs_tentacles.scene.load import load_scene_plugins, read_scene_json, resolve_scene_path
from ecs_tentacles.scene.plugins import scene_first
from ecs_tentacles.scene.spec import CreatureSpec, creature_specs
from ecs_tentacles.settings import Settings
from ecs_tentacles.system import System

# Creatures: a world built with this many has every object made so far moved out of the
# cyclic collector's reach (`gc.freeze`). A crowd's build leaves some million objects
# that live as long as the world; the full collections its first frames set off walked
# all of them each time (5,000 creatures: 5 frames took 5.8 CPU s, 1.4 frozen). A closed
# world unfreezes them (`World.close`); a small world (a test's) is never frozen, so one
# dropped unclosed is collected as usual.
FROZEN_CROWD = 512


class SceneWorld(Host, Protocol):
    """What loading needs of the world it builds (`ecs_tentacles.world.World`)."""

    options: WorldOptions
    froze_build: bool
    layouts: Layouts
    scene: dict[str, object] | None
    scene_dir: pathlib.Path | None
    creature_specs: dict[int, CreatureSpec]

    def adopt(self, plugin: Plugin) -> None: ...
    def build_physics(self, threads: int | None = None) -> object: ...
    def add_systems(self, *systems: System) -> None: ...
    def close(self) -> None: ...


W = TypeVar("W", bound=SceneWorld)
W_co = TypeVar("W_co", bound=SceneWorld, covariant=True)


class WorldClass(Protocol[W_co]):
    """A world class: `World(settings, seed=..., name=...)`."""

    def __call__(
        self, settings: Settings | None = None, *, seed: int = 0, name: str = "world"
    ) -> W_co: ...


def load_world(
    cls: WorldClass[W],
    source: str | os.PathLike[str] | dict[str, object],
    options: WorldOptions | None = None,
    *,
    checks_only: bool = False,
) -> W:
    """A `cls` world built from a scene file, bundled scene name or dict (`World.from_scene`),
    with `options` over what the scene says (`ecs_tentacles.options.WorldOptions`).

    `checks_only` stops once every check a run makes before it simulates has run (the
    scene, the plugins' resources with the files they read, the build hooks, the plugins'
    systems): no physics models are compiled and nothing is scheduled; a scene's own
    `systems` are imported only when allowed (`validate`; close the world after).
    """
    with collection_paused():  # the scene's and the crowd's objects are made, none freed
        world = _load_world(cls, source, options, checks_only)
        if not checks_only and len(world.creature_specs) >= FROZEN_CROWD:
            gc.freeze()  # (`FROZEN_CROWD`) until `World.close` unfreezes
            world.froze_build = True
        return world


def _load_world(
    cls: WorldClass[W],
    source: str | os.PathLike[str] | dict[str, object],
    options: WorldOptions | None,
    checks_only: bool,
) -> W:
    """`load_world`, with the collector off."""
    options = options or WorldOptions()
    allow_systems, plugins, seed = options.allow_systems, options.plugins, options.seed
    folder = options.scene_dir
    if not isinstance(source, dict):
        source = resolve_scene_path(os.fspath(source))  # a path, or a bundled scene's name
        folder = source.resolve().parent
    if plugins:  # the caller's choices over the scene's
        raw = source if isinstance(source, dict) else _read_scene(source)
        given = raw.get("plugins") or {}
        if isinstance(given, Mapping):  # (else the schema reports the scene's own)
            source = {**raw, "plugins": {**given, **plugins}}
    layouts = Layouts()  # each creature's, worked out once: the checks', then the build's
    data, chosen = load_scene_plugins(
        source, allow_systems=allow_systems, scene_dir=folder, layouts=layouts
    )
    if allow_systems or not checks_only:  # validate says what a scene asks to run
        chosen += _scene_systems(data["systems"], folder, allow_systems)
    settings = Settings.from_physics(data["physics"])
    if options.lod is not None:  # the caller's choice over the scene's
        settings = replace(settings, lod=replace(settings.lod, enabled=options.lod))
    world = cls(
        settings,
        seed=data["seed"] if seed is None else seed,
        name=data.get("name", "scene"),
    )
    world.scene, world.scene_dir, world.options = data, folder, options
    world.layouts = layouts
    with stops.deferred():  # a Ctrl-C waits for the next creature (`ecs_tentacles.stops`)
        try:
            _build(world, data, chosen, options.only, checks_only, options.threads)
        finally:
            layouts.clear()  # built: a crowd's layouts would only take memory
    if options.focus is not None and not checks_only:
        x, y, radius = options.focus
        world.physics.lod.focus((x, y), radius)
    return world


@contextlib.contextmanager
def collection_paused() -> Iterator[None]:
    """Python's cyclic garbage collector off inside (as it was, after).

    A build makes about a hundred objects a creature (components, store rows' handles,
    spec dicts) and frees almost none: every collection the allocations set off would
    walk all of them again, a fifth of a 1,024-creature build's time for nothing to free.
    """
    was = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was:
            gc.enable()


def _build(
    world: SceneWorld,
    data: dict[str, object],
    chosen: list[Plugin],
    only: Collection[int] | None,
    checks_only: bool,
    threads: int | None,
) -> None:
    """`load_world`'s entities, physics and systems, built into `world`."""
    try:
        for plugin in chosen:
            world.adopt(plugin)
        for index, creature in enumerate(creature_specs(data)):
            stops.check()
            if only is None or index in only:
                layout = world.layouts.on(creature, ground_of(world))  # the checks' one
                entity = build_creature(world, creature, layout)
                world.creature_specs[entity] = creature
                for plugin in chosen:
                    with calling(plugin, "build_creature"):
                        plugin.build_creature(world, entity, creature)
        for plugin in chosen:
            plugin.build_scene(world, data)
        if checks_only:
            for plugin in chosen:
                _plugin_systems(plugin)
            return
        stops.check()
    except BaseException:  # a bad file, a creature inside a rock, a user's hook, a stop
        world.close()  # its esper context
        raise
    for store in world.stores.values():
        store.fit()  # a crowd's stores were grown by doubling: up to half unused
    world.build_physics(threads)
    try:
        stops.check()
        systems = physics_systems()
        for plugin in chosen:
            systems += _plugin_systems(plugin)
        world.add_systems(*systems)
        for plugin in chosen:
            with calling(plugin, "ready"):
                plugin.ready(world)
    except BaseException:  # a user's systems(), setup() or ready() raised, or a stop
        world.close()  # its physics threads and esper context
        raise


def owned_systems(plugin: Plugin) -> list[System]:
    """The plugin's systems, each tagged with the plugin's key."""
    with calling(plugin, "systems"):
        systems = plugin.systems()
    for system in systems:
        system.plugin = plugin.key
    return systems


def _plugin_systems(plugin: Plugin) -> list[System]:
    """`owned_systems`, a raising `systems()` as one SceneError line naming the plugin."""
    try:
        return owned_systems(plugin)
    except HookFailure:
        raise
    except Exception as exc:  # one line naming the plugin, as for an import
        text = f"{type(exc).__name__}: {' '.join(str(exc).split())}"
        raise SceneError([f"plugins.{plugin.key}: systems() raised {text}"]) from exc


def _scene_systems(
    paths: list[str], folder: pathlib.Path | None, allow_systems: bool
) -> list[Plugin]:
    """The scene's `systems` list as one plugin (none when empty); refused unless allowed."""
    if not paths:
        return []
    if not allow_systems:  # checked before importing anything
        raise SceneError(
            [
                f"systems[{i}]: the scene asks to run {path!r}; allow it with --allow-systems"
                " (API: allow_systems=True)"
                for i, path in enumerate(paths)
            ]
        )
    legacy = SystemsPlugin(_import_systems(paths, folder))
    legacy.key, legacy.source = "systems", "the scene's systems list"
    return [legacy]


def _read_scene(path: pathlib.Path) -> dict[str, object]:
    data = read_scene_json(path)
    if not isinstance(data, dict):
        raise SceneError([f"{path}: scene: must be an object"])
    return data


def _import_systems(paths: list[str], folder: pathlib.Path | None) -> list[type[System]]:
    """Resolve 'package.module:Class' paths to System subclasses (only when allowed).

    The scene's folder is searched first, so a module beside the scene is found.
    """
    found: list[type[System]] = []
    problems: list[str] = []
    for i, path in enumerate(paths):
        module_name, _, attr = path.partition(":")
        try:
            with scene_first(folder):
                factory = getattr(importlib.import_module(module_name), attr)
        except (ImportError, AttributeError) as exc:
            problems.append(f"systems[{i}]: cannot import {path!r}: {exc}")
            continue
        except Exception as exc:  # the user's module raised while importing: say which and why
            problems.append(f"systems[{i}]: cannot import {path!r}: {type(exc).__name__}: {exc}")
            continue
        if not (isinstance(factory, type) and issubclass(factory, System)):
            problems.append(f"systems[{i}]: {path!r} is not a System subclass")
            continue
        found.append(factory)
    if problems:
        raise SceneError(problems)
    return found
