"""Where plugins are, and how a scene's `plugins` become Plugin instances.

A scene turns plugins on and configures them:

    "plugins": {"wander": {"radius": 2.0}, "fur": false, "mine": {"from": "mine.py"}}

Every plugin is found through entry points, the engine's own as any installed
package's (reads `importlib.metadata`; core lists none by name). Three groups:
`ecs_tentacles.plugins` (found by name, on when a scene turns it on), and two roles the
engine's own package declares in its `pyproject.toml`: `ecs_tentacles.plugins.default`
(on unless a scene says `false`, built by their `build_order`) and
`ecs_tentacles.plugins.sandbox` (added by the sandbox to the world it shows). A role is
honoured only for the engine's own entries: another package's plugin, in whichever
group, is on only when a scene names it. A plugin another one `requires` that the
engine ships is turned on with it unless the scene names it (the `game` layer with a
game mode). A fourth group, `ecs_tentacles.plugins.renamed`, maps a key one of the
engine's plugins had before to its key now (`current_keys`: old scenes keep loading).

Trust: the engine's own entry points were consented to when it was installed. A plugin
from a file or module named by `from` (the scene's folder is searched first; a relative
file may not leave it), or from another package's entry point, runs user code, so it
needs `allow_systems` (`--allow-systems`). Nothing here imports a plugin until a world
uses it (targets are "module:Class"), so finding and listing them runs no code.
"""

from __future__ import annotations

import contextlib
import functools
import importlib
import importlib.metadata
import importlib.util
import pathlib
import sys
import warnings
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass
from types import ModuleType

from ecs_tentacles.plugin import Plugin, SystemsPlugin
from ecs_tentacles.system import System

ENTRY_POINTS = "ecs_tentacles.plugins"  # found by name; what third parties register in
DEFAULT_GROUP = f"{ENTRY_POINTS}.default"  # the engine's: on unless a scene says false
SANDBOX_GROUP = f"{ENTRY_POINTS}.sandbox"  # the engine's: added by the sandbox
GROUPS = (DEFAULT_GROUP, SANDBOX_GROUP, ENTRY_POINTS)
RENAMED_GROUP = f"{ENTRY_POINTS}.renamed"  # the engine's: a plugin's former key -> its key
DISTRIBUTION = "ecs-tentacles"  # the engine's own package: its entry points are trusted
FROM = "from"  # the config key naming where a plugin's code is


class PluginError(ValueError):
    """A plugin cannot be found, imported or trusted; the message names the scene path."""


@dataclass(frozen=True)
class Found:
    """Where a plugin's code is and whether running it needs the user's permission."""

    target: str  # "module:Attr", "file.py" or "file.py:Attr"
    trusted: bool


def locate(key: str, config: object) -> Found:
    """Where the plugin turned on as `key` (its `config`: true or an object) lives
    (PluginError if nowhere)."""
    if isinstance(config, Mapping) and FROM in config:
        return Found(str(config[FROM]), trusted=False)
    entries = sorted((e for e in _entry_points() if e.name == key), key=lambda e: not e.ours)
    if entries:  # the engine's own first: another package cannot take a built-in's name
        return Found(entries[0].value, trusted=entries[0].ours)
    known = sorted({e.name for e in _entry_points()})
    raise PluginError(
        f"plugins.{key}: no plugin of that name (known: {', '.join(known)});"
        f' name its code with {{"{FROM}": "file.py"}}'
    )


def shipped() -> dict[str, str]:
    """Every plugin the engine's own package registers: scene key -> "module:Class"."""
    return {e.name: e.value for e in _entry_points() if e.ours}


def default_on() -> tuple[str, ...]:
    """The plugins on unless a scene says `false`, by key (`resolve` builds them by their
    `build_order`, which needs their code: this list imports none)."""
    return _role(DEFAULT_GROUP)


def sandbox_on() -> tuple[str, ...]:
    """The plugins the sandbox (`play`) adds to the world it shows."""
    return _role(SANDBOX_GROUP)


def renamed() -> dict[str, str]:
    """The scene keys the engine's plugins had before -> their keys now."""
    every = _entry_points_on(tuple(sys.path))
    return {e.name: e.value for e in every if e.group == RENAMED_GROUP and e.ours}


def current_keys(scene: object, path: pathlib.Path | None = None) -> object:
    """`scene` with each former plugin key in its `plugins` under the key the plugin has
    now (`renamed()`; a new dict, `scene` untouched), and one `FutureWarning` a key
    naming both keys, issued at the scene file `path`, on the key's line (else at the
    caller). Where a scene has both keys, the new key's value is kept."""
    if not isinstance(scene, dict) or not isinstance(scene.get("plugins"), dict):
        return scene
    chosen: dict[str, object] = scene["plugins"]
    old = renamed()
    if not any(key in old for key in chosen):
        return scene
    current: dict[str, object] = {}
    for key, value in chosen.items():
        new = old.get(key)
        if new is None:
            current.setdefault(key, value)
            continue
        kept = "ignored: plugins." + new + " is set too" if new in chosen else "read as such"
        message = f"plugins.{key} is deprecated: the plugin is now plugins.{new} ({kept})"
        if path is None:
            warnings.warn(message, FutureWarning, stacklevel=3)
        else:
            warnings.warn_explicit(message, FutureWarning, str(path), _line_of(path, key))
        current[new] = chosen.get(new, value)
    return {**scene, "plugins": current}


def _line_of(path: pathlib.Path, key: str) -> int:
    """The line of `path` where `plugins.<key>` is written (the first `"key"` from the
    line that opens `plugins`; 1 if not found)."""
    lines = path.read_text(encoding="utf-8", errors="replace").splitlines()
    start = next((i for i, line in enumerate(lines) if '"plugins"' in line), 0)
    found = (i for i, line in enumerate(lines[start:], start) if f'"{key}"' in line)
    return next(found, 0) + 1


def former_keys(scene: Mapping[str, object]) -> Mapping[str, object]:
    """`scene` with its `plugins` under the keys they had first (`current_keys` undone;
    `scene` itself if none was renamed): the form a scene's hash is taken of, so that a
    scene hashes the same before and after a plugin's rename (a take's `scene_sha256`,
    the shards of a distributed bake)."""
    plugins = scene.get("plugins")
    if not isinstance(plugins, dict):
        return scene
    first = {new: old for old, new in renamed().items()}
    if not any(key in first for key in plugins):
        return scene
    return {**scene, "plugins": {first.get(key, key): value for key, value in plugins.items()}}


def _role(group: str) -> tuple[str, ...]:
    return tuple(sorted(e.name for e in _entry_points() if e.group == group and e.ours))


@dataclass(frozen=True)
class Entry:
    """An installed plugin entry point, read (never loaded), and whether it is the
    engine's own (consented to when the engine was installed)."""

    name: str
    group: str
    value: str  # "module:Class"
    ours: bool


def _entry_points() -> tuple[Entry, ...]:
    """Every installed plugin entry point, of every group (`GROUPS`)."""
    return tuple(e for e in _entry_points_on(tuple(sys.path)) if e.group != RENAMED_GROUP)


@functools.lru_cache(maxsize=8)
def _entry_points_on(path: tuple[str, ...]) -> tuple[Entry, ...]:
    # read once per import path, and each distribution's name once (it is parsed from
    # the distribution's whole METADATA, the engine's README included)
    every = importlib.metadata.entry_points()  # one pass over the installed packages
    found = [e for group in (*GROUPS, RENAMED_GROUP) for e in every.select(group=group)]
    names: dict[int, str] = {}
    for entry in found:
        dist = getattr(entry, "dist", None)
        if dist is not None and id(dist) not in names:
            names[id(dist)] = _distribution(entry)
    return tuple(
        Entry(e.name, e.group, e.value, names.get(id(getattr(e, "dist", None))) == DISTRIBUTION)
        for e in found
    )


def _distribution(entry: importlib.metadata.EntryPoint) -> str:
    """The normalised name of the package that declares `entry` ('' if unknown)."""
    dist = getattr(entry, "dist", None)
    return "" if dist is None else dist.name.replace("_", "-").lower()


def load(
    key: str, target: str, scene_dir: pathlib.Path | None, *, consented: bool = False
) -> type[Plugin] | Plugin:
    """Import the plugin class (or a SystemsPlugin of System classes) that `target` names.

    The scene's folder is on the import path only while a `consented` user plugin is
    imported: a built-in's first import of a library module (`filecmp`, `json`) must
    never find a file of that name beside the scene.
    """
    where = f"plugins.{key}"
    module_part, _, attr = target.partition(":")
    try:
        if module_part.endswith(".py"):
            if not consented:
                raise PluginError(f"{where}: runs code from {target!r}; allow it first")
            module = import_file(inside_scene_folder(module_part, scene_dir, where), key)
        else:
            with scene_first(scene_dir if consented else None):
                module = importlib.import_module(module_part)
    except PluginError:
        raise
    except (Exception, SystemExit, KeyboardInterrupt) as exc:  # the user's module failed
        raise PluginError(f"{where}: cannot import {target!r}: {_one_line(exc)}") from exc
    return pick(module, attr, where, target)


def pick(module: ModuleType, attr: str, where: str, target: str) -> type[Plugin] | Plugin:
    """The Plugin class `attr` of `module` (or its only one), or its System classes wrapped."""
    if attr:
        found = getattr(module, attr, None)
        if isinstance(found, type) and issubclass(found, Plugin):
            return found
        if isinstance(found, type) and issubclass(found, System):
            return SystemsPlugin([found])
        raise PluginError(f"{where}: {target!r} is not a Plugin or System subclass")
    own = [
        v for v in vars(module).values() if isinstance(v, type) and v.__module__ == module.__name__
    ]
    plugins = [v for v in own if issubclass(v, Plugin) and v is not Plugin]
    if len(plugins) == 1:
        return plugins[0]
    systems = [v for v in own if issubclass(v, System)]
    if not plugins and systems:
        return SystemsPlugin(systems)
    what = "several Plugin classes" if plugins else "no Plugin or System class"
    raise PluginError(f"{where}: {target!r} defines {what}; name one as 'file.py:ClassName'")


def inside_scene_folder(relative: str, scene_dir: pathlib.Path | None, where: str) -> pathlib.Path:
    """`relative` resolved (symlinks followed) in the scene's folder; PluginError if it
    leaves the folder or is not a file."""
    base = (scene_dir or pathlib.Path.cwd()).resolve()
    path = (base / relative).resolve()
    if not path.is_relative_to(base):
        raise PluginError(f"{where}: {relative!r} leaves the scene's folder {base}")
    if not path.is_file():
        raise PluginError(f"{where}: no file {relative!r} in the scene's folder {base}")
    return path


def import_file(path: pathlib.Path, key: str) -> ModuleType:
    """Execute a plugin file as a fresh module (again on every call: hot reload uses it)."""
    name = f"ecs_tentacles_user_plugins.{key}"
    spec = importlib.util.spec_from_file_location(name, path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module  # dataclasses and pickling look classes up here
    with scene_first(path.parent):
        try:
            spec.loader.exec_module(module)
        except BaseException:
            sys.modules.pop(name, None)
            raise
    return module


@contextlib.contextmanager
def scene_first(folder: pathlib.Path | None) -> Iterator[None]:
    """The scene's folder first on `sys.path` while importing, so modules beside it import."""
    if folder is None:
        yield
        return
    entry = str(folder.resolve())
    sys.path.insert(0, entry)
    try:
        yield
    finally:
        with contextlib.suppress(ValueError):
            sys.path.remove(entry)


def instantiate(
    made: type[Plugin] | Plugin, key: str, config: Mapping[str, object], source: str | None
) -> Plugin:
    """The plugin `load` found, made with `config` and known as `key` (from `source`)."""
    plugin = made if isinstance(made, Plugin) else made(dict(config))
    plugin.config, plugin.key, plugin.source = dict(config), key, source
    return plugin


def builtin(key: str, **options: object) -> Plugin:
    """The engine's plugin `key`, made with keyword `options` (a bake's record plugin:
    `builtin("record", every=2)`), so generic code needs no feature's import."""
    known = shipped()
    if key not in known:
        raise PluginError(f"plugins.{key}: not a built-in plugin (known: {', '.join(known)})")
    made = load(key, known[key], None)
    if isinstance(made, Plugin):
        return instantiate(made, key, {}, None)
    make: Callable[..., Plugin] = made  # the plugin class: its own keywords
    return instantiate(make(**options), key, {}, None)


def sandbox_plugins() -> list[Plugin]:
    """The engine's plugins every sandbox adds to its world (`sandbox_on()`)."""
    return [builtin(key) for key in sandbox_on()]


def resolve(
    choices: Mapping[str, object] | None,
    scene_dir: pathlib.Path | None = None,
    *,
    allow: bool = False,
    defaults: tuple[str, ...] | None = None,
    problems_out: list[str] | None = None,
) -> list[Plugin]:
    """Instances of the plugins a scene's `plugins` field turns on, defaults first.

    `choices` maps names to `true`, `false` or a config (configs are not validated
    here: the scene schema does that). Raises PluginError, one problem per line; with
    `problems_out`, the problems go there instead and the plugins that could be made
    are returned (the loader goes on to check the rest of the scene).
    """
    choices = dict(choices or {})
    defaults = default_on() if defaults is None else defaults
    wanted = [n for n in defaults if choices.get(n, True) is not False]
    wanted += [n for n in choices if n not in wanted and choices[n] is not False]
    problems: list[str] = []
    plugins: list[Plugin] = []
    for key in wanted:
        config = choices.get(key, True)
        try:
            found = locate(key, config)
            if not found.trusted and not allow:
                raise PluginError(
                    f"plugins.{key}: runs code from {found.target!r}; allow it with"
                    " --allow-systems (API: allow_systems=True)"
                )
            made = load(key, found.target, scene_dir, consented=not found.trusted)
        except PluginError as exc:
            problems.append(str(exc))
            continue
        settings = (
            {k: v for k, v in config.items() if k != FROM} if isinstance(config, Mapping) else {}
        )
        try:
            plugins.append(
                instantiate(made, key, settings, None if found.trusted else found.target)
            )
        except (Exception, SystemExit) as exc:  # the user's plugin class failed to construct
            problems.append(f"plugins.{key}: cannot make {found.target!r}: {_one_line(exc)}")
    first = set(defaults)
    plugins.sort(key=lambda p: (0, p.build_order, p.key) if p.key in first else (1, 0, ""))
    on = {p.key for p in plugins}
    known = shipped()
    for plugin in list(plugins):
        for need in plugin.requires:
            if need in on:
                continue
            if need in known and need not in choices:  # a layer it needs, on with it
                brought = instantiate(load(need, known[need], None), need, {}, None)
                plugins.insert(plugins.index(plugin), brought)
                on.add(need)
            else:
                problems.append(f"plugins.{plugin.key}: needs the {need!r} plugin, which is off")
    if problems and problems_out is None:
        raise PluginError("\n".join(problems))
    if problems_out is not None:
        problems_out += problems
    return plugins


def _one_line(error: BaseException) -> str:
    """`Type: message` on one line (a user's exception, for a PluginError)."""
    text = " ".join(str(error).split())
    return type(error).__name__ + (f": {text}" if text else "")
