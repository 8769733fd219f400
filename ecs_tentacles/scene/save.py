"""Writing a scene: validated first, then JSON written through the one atomic writer.

A scene names files relative to its folder (a heightfield image, meshes, plugin code).
Saved in another folder, it takes copies of them along (`carried_files`), at the same
names beside it, so the saved file loads from there; another file already at such a
name is never overwritten: the save is refused, saying which.

`default_file_name` makes the file name a save offers by default from the scene's
`name`, which is any string a scene file says: it only ever names a file in the current
folder, never a folder (no separators, `..`, control characters or ANSI codes), and one
the file system takes: at most `NAME_MAX` bytes of UTF-8 with the atomic writer's
temporary name (`.<name>.<token>.partial<suffix>`) included, cut between characters.
"""

from __future__ import annotations

import contextlib
import copy
import filecmp
import json
import os
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from importlib.resources import files
from pathlib import Path
from typing import TYPE_CHECKING

from ecs_tentacles.output.atomic import AtomicOutput, OutputError, disk_full, temporary_name
from ecs_tentacles.scene.errors import SceneError
from ecs_tentacles.scene.load import load_scene_plugins, on_plane
from ecs_tentacles.scene.physical import physically_checked
from ecs_tentacles.scene.validate import format_path, json_child, validated

if TYPE_CHECKING:
    from ecs_tentacles.plugin import Plugin

MAX_STEM = 64  # characters of the scene's name a default file name keeps
NAME_MAX = 255  # bytes of a file name (ext4, XFS, btrfs, APFS; 64 four-byte letters are 256)
# what the atomic writer's temporary name adds to the target's (`.` and `.<token>.partial`)
_PARTIAL_BYTES = len(temporary_name(Path("x.json"), "0" * 8).name) - len("x.json")
_ANSI = re.compile(r"\x1b(\[[0-?]*[ -/]*[@-~]|[@-_])")  # colour codes etc., taken out whole
_UNSAFE = re.compile(r"[^\w.-]+")  # separators, spaces, controls, NUL, punctuation
_DOTS = re.compile(r"\.{2,}")


def default_file_name(name: object, suffix: str, fallback: str = "scene") -> str:
    """`<name><suffix>` as a bare file name (`"../x"` -> `"x_directed.json"`): a path's
    last part only; characters other than letters, digits, `_`, `.` and `-` become
    `_`, runs of dots one dot, the ends lose dots, `_` and `-`; at most `MAX_STEM`
    characters, and few enough bytes that the name and its temporary file's fit in
    `NAME_MAX` (the stem cut between characters, `suffix` kept whole); `fallback` if
    nothing is left (or `name` is not a string)."""
    text = _ANSI.sub("", name) if isinstance(name, str) else ""
    text = re.split(r"[/\\]", text)[-1]
    text = _DOTS.sub(".", _UNSAFE.sub("_", text)).strip("._-")
    room = NAME_MAX - _PARTIAL_BYTES - len(suffix.encode())
    cut = text[:MAX_STEM].encode()[: max(room, 0)].decode(errors="ignore")
    stem = cut.strip("._-") or fallback
    return stem + suffix


def checked_scene(
    scene: dict[str, object], plugins: Sequence[Plugin] | None = None
) -> tuple[dict[str, object], list[Plugin]]:
    """`scene` validated and completed as `load_scene` does (SceneError, one line per
    problem), and the plugins that checked it: `plugins`, a running world's, already
    made, so no plugin is looked up or imported again (a `spawner.py` in the current
    folder never runs); without them, the plugins the scene names, of which only
    trusted ones are imported."""
    if plugins is None:
        return load_scene_plugins(scene)
    problems, completed = validated(scene, plugins)
    if problems or completed is None:
        raise SceneError(problems or ["the scene is not an object"])
    return physically_checked(completed, plane=on_plane(completed, plugins)), list(plugins)


@dataclass(frozen=True)
class Carried:
    """A file a scene names, copied beside the scene saved in another folder."""

    where: str  # its JSON path
    source: Path  # in the scene's folder (resolved)
    destination: Path  # in the saved scene's folder


def named_files(
    scene: Mapping[str, object], plugins: Sequence[Plugin]
) -> list[tuple[tuple[str | int, ...], str]]:
    """Every file `scene` names relative to its folder, as (JSON path, name): plugin code
    (`plugins.<key>.from: "file.py"`) and what each plugin's keys name
    (`Plugin.scene_files`)."""
    found: list[tuple[tuple[str | int, ...], str]] = []
    chosen = scene.get("plugins")
    for key, config in chosen.items() if isinstance(chosen, Mapping) else ():
        target = config.get("from") if isinstance(config, Mapping) else None
        if isinstance(target, str) and target.partition(":")[0].endswith(".py"):
            found.append((("plugins", key, "from"), target))
    for plugin in plugins:
        found += plugin.scene_files(scene)
    return found


def carried_files(
    scene: dict[str, object], plugins: Sequence[Plugin], source_dir: Path | None, target: Path
) -> list[Carried]:
    """The files `scene` (from `source_dir`) names that a copy saved as `target` in
    another folder needs beside it, at the same names; `scene` is changed where a name
    has to be (an absolute path in its folder becomes relative). Nothing when it is
    saved in its own folder. SceneError, one line each, when a file is not in the
    scene's folder or another file already has its name in the new one."""
    if source_dir is None:  # a scene from a dict: it cannot have named files
        return []
    base, folder = source_dir.resolve(), target.parent.resolve()
    if folder == base:
        return []
    carried: dict[Path, Carried] = {}
    problems: list[str] = []
    for path, written in named_files(scene, plugins):
        where = format_path(path)
        name, colon, attribute = (
            written.partition(":") if path[0] == "plugins" else (written, "", "")
        )
        source = (base / name).resolve()
        if not source.is_relative_to(base) or not source.is_file():
            problems.append(f"{where}: {name}: no such file in the scene's folder ({base})")
            continue
        lexical = Path(os.path.normpath(base / name))
        relative = lexical.relative_to(base) if lexical.is_relative_to(base) else None
        relative = relative or source.relative_to(base)
        destination = folder / relative
        if relative.as_posix() != name:
            _set(scene, path, relative.as_posix() + colon + attribute)
        if destination in carried or destination.resolve() == source:
            continue
        if os.path.lexists(destination) and not _same_content(source, destination):
            problems.append(
                f"{where}: {destination} is another file already; save the scene in another"
                f" folder or in {base}"
            )
            continue
        if not os.path.lexists(destination):
            carried[destination] = Carried(where, source, destination)
    if problems:
        raise SceneError(problems)
    return list(carried.values())


def _same_content(source: Path, destination: Path) -> bool:
    """True when `destination` is a regular file (not a link) holding what `source` holds."""
    try:
        return (
            not destination.is_symlink()
            and destination.is_file()
            and filecmp.cmp(source, destination, shallow=False)
        )
    except OSError:
        return False


def _set(scene: dict[str, object], path: tuple[str | int, ...], value: str) -> None:
    node: object = scene
    for step in path[:-1]:
        node = json_child(node, step)
    if isinstance(node, dict):
        node[path[-1]] = value
    elif isinstance(node, list) and isinstance(path[-1], int):
        node[path[-1]] = value
    else:
        raise TypeError(f"{format_path(path)}: not in an object or a list")


def save_scene(
    scene: dict[str, object],
    path: str | os.PathLike[str],
    plugins: Sequence[Plugin] | None = None,
    *,
    source_dir: Path | None = None,
    indent: int = 1,
) -> Path:
    """Validate `scene` (`checked_scene`: SceneError listing the problems if not) and
    write it to `path`; in another folder than its own (`source_dir`), with copies of
    the files it names beside it (`carried_files`). The copies and the scene are written
    whole or not at all: a copy already made is removed if a later file fails."""
    _, checking = checked_scene(scene, plugins)
    target = Path(path)
    if not target.parent.is_dir():
        raise OutputError(f"{target}: folder {str(target.parent)!r} does not exist")
    scene = copy.deepcopy(scene)
    point_schema(scene, target.parent)
    carried = carried_files(scene, checking, source_dir, target)
    folder = target.parent.resolve()
    outputs: list[AtomicOutput] = []
    made: list[Path] = []  # copies and folders that were not there before
    try:
        for item in carried:
            needed = [p for p in item.destination.parents if p.is_relative_to(folder)]
            for parent in reversed(needed):  # "maps/hill.png": the folder maps first
                if not parent.exists():
                    parent.mkdir()
                    made.append(parent)
            outputs.append(_written(item.destination, item.source.read_bytes()))
        text = json.dumps(scene, indent=indent) + "\n"
        outputs.append(_written(target, text.encode("utf-8")))
        for output in outputs[:-1]:  # the copies first: the scene appears last
            made.append(output.commit(same_file=True))
        outputs[-1].commit(same_file=True)
    except BaseException:
        for output in outputs:
            output.discard()
        for leftover in reversed(made):
            with contextlib.suppress(OSError):
                leftover.rmdir() if leftover.is_dir() else leftover.unlink()
        raise
    return target


def point_schema(scene: dict[str, object], folder: Path) -> None:
    """A scene's `$schema` (what editors complete and check against) rewritten to reach
    the bundled schema from `folder`, where the scene is saved; dropped when no relative
    path reaches it (another drive): loading validates by the bundled schema anyway."""
    if "$schema" not in scene:
        return
    bundled = Path(str(files("ecs_tentacles.assets") / "schema" / "scene.schema.json"))
    try:
        scene["$schema"] = Path(os.path.relpath(bundled, folder.resolve())).as_posix()
    except ValueError:
        del scene["$schema"]


def _written(target: Path, data: bytes) -> AtomicOutput:
    """An opened `AtomicOutput` for `target` holding `data`, to commit (a full disk is
    one line naming `target`)."""
    output = AtomicOutput(target)
    try:
        with os.fdopen(output.open(), "wb") as handle:
            handle.write(data)
    except BaseException as error:
        output.discard()
        full = disk_full(target, error)
        if full is not None:
            raise full from None
        raise
    return output
