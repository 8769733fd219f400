"""Writing a scene: validated first, then JSON written through the one atomic writer.

`default_file_name` makes the file name a save offers by default from the scene's
`name`, which is any string a scene file says: it only ever names a file in the current
folder, never a folder (no separators, `..`, control characters or ANSI codes).
"""

from __future__ import annotations

import json
import os
import re
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ecs_tentacles.atomic import atomic_output
from ecs_tentacles.scene.errors import SceneError
from ecs_tentacles.scene.load import load_scene
from ecs_tentacles.scene.physical import physically_checked
from ecs_tentacles.scene.validate import validated

if TYPE_CHECKING:
    from ecs_tentacles.plugin import Plugin

MAX_STEM = 64  # characters of the scene's name a default file name keeps
_ANSI = re.compile(r"\x1b(\[[0-?]*[ -/]*[@-~]|[@-_])")  # colour codes etc., taken out whole
_UNSAFE = re.compile(r"[^\w.-]+")  # separators, spaces, controls, NUL, punctuation
_DOTS = re.compile(r"\.{2,}")


def default_file_name(name: object, suffix: str, fallback: str = "scene") -> str:
    """`<name><suffix>` as a bare file name (`"../x"` -> `"x_directed.json"`): a path's
    last part only; characters other than letters, digits, `_`, `.` and `-` become
    `_`, runs of dots one dot, the ends lose dots, `_` and `-`; at most `MAX_STEM`
    characters; `fallback` if nothing is left (or `name` is not a string)."""
    text = _ANSI.sub("", name) if isinstance(name, str) else ""
    text = re.split(r"[/\\]", text)[-1]
    text = _DOTS.sub(".", _UNSAFE.sub("_", text)).strip("._-")
    stem = text[:MAX_STEM].strip("._-") or fallback
    return stem + suffix


def checked_scene(scene: dict[str, Any], plugins: Sequence[Plugin] | None = None) -> dict[str, Any]:
    """`scene` validated and completed as `load_scene` does (SceneError, one line per
    problem), by `plugins`: a running world's, already made, so no plugin is looked up
    or imported again (a `spawner.py` in the current folder never runs). Without them,
    by the plugins the scene names, of which only trusted ones are imported."""
    if plugins is None:
        return load_scene(scene)
    problems, completed = validated(scene, plugins)
    if problems or completed is None:
        raise SceneError(problems or ["the scene is not an object"])
    return physically_checked(completed)


def save_scene(
    scene: dict[str, Any],
    path: str | os.PathLike[str],
    plugins: Sequence[Plugin] | None = None,
) -> Path:
    """Validate `scene` (`checked_scene`: SceneError listing the problems if not) and
    write it atomically."""
    checked_scene(scene, plugins)
    target = Path(path)
    with atomic_output(target) as temporary:
        temporary.write_text(json.dumps(scene, indent=1) + "\n", encoding="utf-8")
    return target
