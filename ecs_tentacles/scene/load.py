"""Load a scene from a JSON file (or an already-parsed dict), validate it, fill defaults.

Scenes are data only: they are parsed with :mod:`json` and nothing in them is executed
or imported here (``systems`` import paths are only strings at this stage).
"""

from __future__ import annotations

import importlib.resources
import json
import os
import pathlib
import re
from typing import Any

from ecs_tentacles.scene.errors import SceneError
from ecs_tentacles.scene.physical import physically_checked
from ecs_tentacles.scene.validate import validate_scene, with_defaults

_SCENE_NAME = re.compile(r"^[A-Za-z0-9_][A-Za-z0-9_.-]*$")


def _finite_float(text: str) -> float:
    """Parse a JSON number, refusing ones too large for a float (1e400 would be inf)."""
    value = float(text)
    if value in (float("inf"), float("-inf")):
        raise ValueError(f"number {text} is too large")
    return value


def _refuse_constant(name: str) -> Any:
    """Refuse the non-standard ``NaN``/``Infinity`` literals Python's json accepts."""
    raise ValueError(f"{name} is not valid JSON")


def _read_json(path: pathlib.Path) -> object:
    """Read and parse ``path``, raising SceneError with a one-line, located problem."""
    try:
        text = path.read_text(encoding="utf-8-sig")
    except UnicodeDecodeError as exc:
        raise SceneError([f"{path}: cannot read scene: not UTF-8 text ({exc.reason})"]) from None
    except OSError as exc:
        raise SceneError([f"{path}: cannot read scene: {exc.strerror or exc}"]) from None
    try:
        return json.loads(text, parse_float=_finite_float, parse_constant=_refuse_constant)
    except json.JSONDecodeError as exc:
        raise SceneError([f"{path}:{exc.lineno}:{exc.colno}: invalid JSON: {exc.msg}"]) from None
    except ValueError as exc:
        raise SceneError([f"{path}: invalid JSON: {exc}"]) from None
    except RecursionError:
        raise SceneError([f"{path}: invalid JSON: nested too deeply"]) from None


def load_scene(source: str | os.PathLike[str] | dict[str, Any]) -> dict[str, Any]:
    """Load, validate and complete a scene.

    ``source`` is a path to a JSON file or an already-parsed dict (which is not
    modified). Returns a new dict with every schema default filled in (see
    :func:`with_defaults`). Raises :class:`SceneError` listing every problem, one line
    each; problems found in a file are prefixed with ``"<path>: "``.
    """
    if isinstance(source, dict):
        data: object = source
        prefix = ""
    else:
        path = pathlib.Path(source)
        data = _read_json(path)
        prefix = f"{path}: "
    problems = validate_scene(data)
    if problems:
        raise SceneError([prefix + problem for problem in problems])
    assert isinstance(data, dict)  # the schema requires an object
    return physically_checked(with_defaults(data), prefix)


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
    if not _SCENE_NAME.match(stem) or not path.is_file():
        available = ", ".join(bundled_scene_names()) or "none"
        raise SceneError([f"{name}: no such bundled scene (available: {available})"])
    return path


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
