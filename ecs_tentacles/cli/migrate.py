"""`ecs-tentacles migrate SCENE`: write a scene in today's form (explicit `plugins`).

Old scenes stay valid (the default plugins are on), so migrating is optional. It
writes every plugin the scene runs under `plugins`, with its full config, turns
the older `systems` list of import paths into plugin entries (`{"from": "module:Class"}`)
so they are configured like any plugin, and removes the keys of built-in plugins the
scene turns off (an older scene with locomotion off may carry tentacle waves, which
are the locomotion plugin's keys now), and writes a plugin's former key under its key
now (`plugins.lod` -> `plugins.clips`; the loader reads the old key too, with a warning).
The result is validated before it is written, atomically, to `--out` (default: beside
the scene, `<name>.migrated.json`) or over the scene with `--in-place`.
"""

from __future__ import annotations

import argparse
import copy
import json
import pathlib
import sys
from collections.abc import Mapping

from ecs_tentacles.cli.arguments import output_path, read_only_problem
from ecs_tentacles.output.atomic import atomic_output, claim
from ecs_tentacles.scene.errors import SceneError
from ecs_tentacles.scene.load import load_scene_plugins, read_scene_json, resolve_scene_path
from ecs_tentacles.scene.plugins import FROM, default_on, renamed, shipped
from ecs_tentacles.scene.schema import builtin_keys


def add_parser(commands: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    parser = commands.add_parser(
        "migrate",
        help="rewrite a scene with an explicit plugins block (systems list -> plugins)",
        description="Write the scene with every plugin it runs listed under `plugins` (with"
        " its config) and its `systems` list turned into plugin entries. The output is"
        " validated, then written atomically.",
    )
    parser.add_argument(
        "scene",
        metavar="SCENE",
        help="scene file or bundled scene name (bundled scenes are read-only: their copy is"
        " written to the current folder)",
    )
    where = parser.add_mutually_exclusive_group()
    where.add_argument(
        "--out",
        type=output_path(".json"),
        metavar="FILE",
        help="output file (default SCENE.migrated.json beside the scene)",
    )
    where.add_argument(
        "--in-place",
        action="store_true",
        help="replace the scene file (a symlink stays a link: its target is replaced)",
    )
    parser.add_argument(
        "--allow-systems",
        action="store_true",
        help="import the plugins the scene names to check them",
    )
    parser.add_argument("--json", action="store_true", help="print the summary as JSON")
    parser.set_defaults(handler=handle)


def migrate(raw: Mapping[str, object]) -> tuple[dict[str, object], list[str]]:
    """The scene with `plugins` explicit and `systems` folded in; and what changed."""
    scene = dict(copy.deepcopy(raw))
    changes: list[str] = []
    plugins: dict[str, object] = {}
    old = renamed()
    given = scene.get("plugins")
    named: dict[str, object] = given if isinstance(given, dict) else {}
    for key, value in named.items():
        if key in old:
            changes.append(f"plugins.{key} -> plugins.{old[key]} (the plugin's key now)")
        if old.get(key, key) not in plugins or key not in old:  # the new key's value wins
            plugins[old.get(key, key)] = value
    for name in default_on():
        if name not in plugins:
            plugins[name] = {}
            changes.append(f"plugins.{name}: on (it was on by default)")
    systems = scene.pop("systems", None)
    for i, target in enumerate(systems if isinstance(systems, list) else []):
        key = target.rpartition(":")[2].lower() or f"system_{i}"
        while key in plugins:
            key += "_"
        plugins[key] = {FROM: target}
        changes.append(f"systems[{i}] -> plugins.{key} (from {target})")
    scene["plugins"] = plugins
    changes += _drop_keys_of_plugins_off(scene, [n for n in shipped() if plugins.get(n) is False])
    return scene, changes


def _drop_keys_of_plugins_off(scene: dict[str, object], off: list[str]) -> list[str]:
    """Remove the keys of built-in plugins the scene turns off (they would do nothing,
    and are refused): scene keys, creature keys, tentacle keys and their overrides'.
    Scenes written before the six locomotion tentacle keys moved out of the core schema
    (speed, target_angle_deg, waves, writhe) with locomotion off need this."""
    changes: list[str] = []
    for name in off:
        keys = builtin_keys(name)
        for key in sorted(keys.get("scene", set()) & set(scene)):
            del scene[key]
            changes.append(f"{key}: removed (the {name} plugin is off)")
        creatures = scene.get("creatures")
        for i, creature in enumerate(creatures if isinstance(creatures, list) else []):
            if not isinstance(creature, dict):
                continue
            for key in sorted(keys.get("creature", set()) & set(creature)):
                del creature[key]
                changes.append(f"creatures[{i}].{key}: removed (the {name} plugin is off)")
            tentacles = creature.get("tentacles")
            if not isinstance(tentacles, dict):
                continue
            places = [(f"creatures[{i}].tentacles", tentacles)] + [
                (f"creatures[{i}].tentacles.overrides[{j}]", o)
                for j, o in enumerate(tentacles.get("overrides") or [])
                if isinstance(o, dict)
            ]
            for where, entry in places:
                for key in sorted(keys.get("tentacles", set()) & set(entry)):
                    del entry[key]
                    changes.append(f"{where}.{key}: removed (the {name} plugin is off)")
    return changes


def handle(args: argparse.Namespace) -> int:
    path = resolve_scene_path(args.scene)
    raw = read_scene_json(path)
    if not isinstance(raw, dict):
        raise SceneError([f"{path}: scene: must be an object"])
    scene, changes = migrate(raw)
    folder = path.resolve().parent
    load_scene_plugins(scene, allow_systems=args.allow_systems, scene_dir=folder)
    bundled = read_only_problem(path)
    if args.in_place:
        if bundled:
            raise SceneError(
                [f"{args.scene}: a bundled scene is read-only; write a copy with --out FILE"]
            )
        target = path.resolve()  # through a symlink: the link stays, its file is rewritten
        claim(target)
    elif args.out is not None:
        target = args.out
    else:
        target = path.with_suffix(".migrated.json")
        if bundled:
            target = pathlib.Path(f"{path.stem}.migrated.json")
            print(f"migrate: {args.scene} is a bundled scene: writing the copy to ./{target}",
                  file=sys.stderr)  # fmt: skip
        claim(target)
    with atomic_output(target) as temporary:
        temporary.write_text(json.dumps(scene, indent=2) + "\n", encoding="utf-8")
    if args.json:
        print(json.dumps({"scene": str(path), "out": str(target), "changes": changes}))
    else:
        print(f"migrate: {path} -> {target}: {len(changes)} changes")
        for change in changes:
            print(f"  {change}")
    return 0
