"""Load a scene from a JSON file (or an already-parsed dict), validate it, fill defaults.

Scenes are data only: they are parsed with :mod:`json` (every key once in its object,
numbers finite: `untrusted.strict_json.strict_loads`), and the only code imported is
the plugins the scene turns on: built-in and bundled ones by name, others (a file
beside the scene, a module, an installed entry point) only with ``allow_systems``.
``systems`` import paths are only strings at this stage.

Scene files are untrusted input: only regular files are read (a FIFO or a device is
refused without blocking), at most ``MAX_SCENE_BYTES`` of them (the CLI's
``--max-scene-mb`` changes it), and data nested deeper than ``validate.MAX_DEPTH`` or
with arrays over the schema's ``maxItems`` is refused before it is walked further.
"""

from __future__ import annotations

import difflib
import importlib.resources
import json
import os
import pathlib
import re
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

from ecs_tentacles.scene.defaults import plugin_config, with_defaults
from ecs_tentacles.scene.errors import SceneError
from ecs_tentacles.scene.layouts import Layouts
from ecs_tentacles.scene.physical import physical_problems, physically_checked
from ecs_tentacles.scene.plugins import current_keys, resolve
from ecs_tentacles.scene.validate import repaired, validated
from ecs_tentacles.untrusted.files import TooLarge, Unfit, read_regular
from ecs_tentacles.untrusted.strict_json import DuplicateKey, strict_loads

if TYPE_CHECKING:
    from ecs_tentacles.plugin import Plugin

# bundled scenes are a few kB; `crowd 16384` (the most creatures a scene holds) writes 14 MB
MAX_SCENE_BYTES = 16 * 1024**2
_SCENE_NAME = re.compile(r"^[A-Za-z0-9_][A-Za-z0-9_.-]*$")


def _read_text(path: pathlib.Path) -> str:
    """The file's text: a regular file of at most `MAX_SCENE_BYTES`, opened without blocking."""
    try:
        data = read_regular(path, MAX_SCENE_BYTES)
    except TooLarge:
        raise SceneError(
            [
                f"{path}: cannot read scene: larger than {MAX_SCENE_BYTES / 1024**2:g} MB"
                " (raise the limit with --max-scene-mb)"
            ]
        ) from None
    except Unfit as unfit:
        raise SceneError([f"{path}: cannot read scene: {unfit.reason}"]) from None
    return data.decode("utf-8-sig")


def read_scene_json(path: pathlib.Path) -> object:
    """Read and parse ``path``, raising SceneError with a one-line, located problem."""
    try:
        text = _read_text(path)
    except UnicodeDecodeError as exc:
        raise SceneError([f"{path}: cannot read scene: not UTF-8 text ({exc.reason})"]) from None
    except FileNotFoundError as exc:
        if len(path.parts) == 1:  # a bare name: perhaps a misspelt bundled scene
            raise SceneError(
                [f"{path}: no such file or bundled scene{_suggestion(path)}"]
            ) from None
        raise SceneError([f"{path}: cannot read scene: {exc.strerror}"]) from None
    except OSError as exc:
        raise SceneError([f"{path}: cannot read scene: {exc.strerror or exc}"]) from None
    try:
        return strict_loads(text)
    except json.JSONDecodeError as exc:
        raise SceneError([f"{path}:{exc.lineno}:{exc.colno}: invalid JSON: {exc.msg}"]) from None
    except DuplicateKey as exc:
        where = f":{exc.line}:{exc.column}" if exc.line is not None else ""
        key = json.dumps(exc.key, ensure_ascii=False)
        raise SceneError([f"{path}{where}: invalid JSON: key {key} written twice"]) from None
    except ValueError as exc:
        raise SceneError([f"{path}: invalid JSON: {exc}"]) from None
    except RecursionError:
        raise SceneError([f"{path}: invalid JSON: nested too deeply"]) from None


def load_scene(
    source: str | os.PathLike[str] | dict[str, object], *, allow_systems: bool = False
) -> dict[str, Any]:
    """Load, validate and complete a scene.

    ``source`` is a path to a JSON file or an already-parsed dict (which is not
    modified). Returns a new dict with every schema default filled in (see
    :func:`with_defaults`), `plugins` listing every plugin on with its full config.
    Raises :class:`SceneError` listing every problem, one line each; problems found in
    a file are prefixed with ``"<path>: "``.
    """
    return load_scene_plugins(source, allow_systems=allow_systems)[0]


def _later_problems(data: object, found: list[str], plugins: list[Plugin]) -> list[str]:
    """The problems the later stages find in `data` while earlier ones are reported:
    semantic checks once the schema's are taken out (`validate.repaired`), physical
    checks once both are; each problem once, after those already `found`."""
    fixed = repaired(data, plugins)
    if fixed is None:
        return []
    semantic, completed = validated(fixed, plugins)
    later = [problem for problem in semantic if problem not in found]
    try:  # a semantic problem (an override of a tentacle that is not there) may stop it
        whole = completed or with_defaults(fixed, plugins)
        physical = physical_problems(whole, on_plane(whole, plugins))
    except (KeyError, IndexError, TypeError, ValueError):
        physical = []
    later += [problem for problem in physical if problem not in found]
    return [problem for problem in later if not _caused_by_repair(problem, found)]


def on_plane(scene: Mapping[str, object], plugins: Sequence[Plugin]) -> bool:
    """Whether the creatures of `scene` stand on the plane z = 0: no plugin on shapes the
    ground there (`Plugin.shapes_ground`)."""
    return not any(plugin.shapes_ground(scene) for plugin in plugins)


def _caused_by_repair(problem: str, found: list[str]) -> bool:
    """True when `problem`, found in the repaired scene, is about an object one of whose
    keys the repair took out because of a problem `found`, and names that key (a NaN
    `radius` taken out is not also a sphere that "needs 'radius'"; a numpy `heights`
    not also a heightfield without one of "noise, image or heights")."""
    where, _, message = problem.partition(": ")
    for earlier in found:
        path = earlier.partition(": ")[0]
        key = path[len(where) + 1 :] if path.startswith(where + ".") else ""
        if key.isidentifier() and re.search(rf"\b{key}\b", message):
            return True
    return False


def load_scene_plugins(
    source: str | os.PathLike[str] | dict[str, object],
    *,
    allow_systems: bool = False,
    scene_dir: pathlib.Path | None = None,
    layouts: Layouts | None = None,
) -> tuple[dict[str, Any], list[Plugin]]:
    """`load_scene`, and the plugins the scene turns on, configured (in build order).

    Plugins from a file are looked up in the scene's folder (`scene_dir` for a dict;
    default: the current folder). The physical checks lay the creatures out in
    `layouts` (the loader's, which the build then reuses).
    """
    # (a plugin's former key in `plugins` is read as its key now, with a warning)
    if isinstance(source, dict):
        data: object = current_keys(source)
        prefix = ""
    else:
        path = pathlib.Path(source)
        data = current_keys(read_scene_json(path), path)
        prefix = f"{path}: "
        scene_dir = path.resolve().parent
    chosen = data.get("plugins") if isinstance(data, dict) else None
    plugin_problems: list[str] = []
    plugins = resolve(
        chosen if _plugin_choices(chosen) else None,
        scene_dir,
        allow=allow_systems,
        problems_out=plugin_problems,
    )
    problems, completed = validated(data, plugins)
    if plugin_problems or problems:
        problems = plugin_problems + problems + _later_problems(data, problems, plugins)
        raise SceneError([prefix + problem for problem in problems])
    assert isinstance(data, dict) and completed is not None  # the schema requires an object
    full = physically_checked(completed, prefix, on_plane(completed, plugins), layouts)
    for plugin in plugins:
        config = plugin_config(plugin, (data.get("plugins") or {}).get(plugin.key))
        plugin.config = {k: v for k, v in config.items() if k != "from"}
    return full, plugins


def _plugin_choices(chosen: object) -> bool:
    """True when `plugins` has the shape the schema asks (else the schema reports it)."""
    return isinstance(chosen, dict) and all(
        isinstance(k, str) and (isinstance(v, bool) or isinstance(v, dict))
        for k, v in chosen.items()
    )


def _scenes_dir() -> pathlib.Path:
    """The folder holding the scenes bundled with the package."""
    return pathlib.Path(str(importlib.resources.files("ecs_tentacles.assets") / "scenes"))


def bundled_scene_names() -> list[str]:
    """Names (without ``.json``) of the bundled scenes, sorted."""
    folder = _scenes_dir()
    return sorted(p.stem for p in folder.glob("*.json")) if folder.is_dir() else []


def bundled_scene(name: str) -> pathlib.Path:
    """Return the path of the bundled scene ``name`` (``"octopus"`` or ``"octopus.json"``).

    Raises :class:`SceneError` if there is no such bundled scene; the message lists the
    available ones.
    """
    stem = name.removesuffix(".json")
    path = _scenes_dir() / f"{stem}.json"
    if not _SCENE_NAME.fullmatch(stem) or not path.is_file():
        available = ", ".join(bundled_scene_names()) or "none"
        hint = _suggestion(pathlib.Path(name)) or f" (available: {available})"
        raise SceneError([f"{name}: no such bundled scene{hint}"])
    return path


def _suggestion(path: pathlib.Path) -> str:
    """`; did you mean 'octopus'?` for a bare name close to a bundled scene's, else ''."""
    if len(path.parts) != 1:
        return ""
    close = difflib.get_close_matches(path.name.removesuffix(".json"), bundled_scene_names(), 1)
    return f"; did you mean {close[0]!r}?" if close else ""


def resolve_scene_path(arg: str) -> pathlib.Path:
    """Turn a command-line scene argument into a path.

    An existing path is returned as given; otherwise a bundled scene name is resolved
    with :func:`bundled_scene`; otherwise the path is returned unchanged so that
    :func:`load_scene` reports it as unreadable.
    """
    path = pathlib.Path(arg)
    if path.exists():
        return path
    try:
        return bundled_scene(arg)
    except SceneError:
        return path
