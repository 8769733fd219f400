"""`ecs-tentacles schema [SCENE]`: the whole scene schema, for editors and tools.

`assets/schema/core.schema.json` is the core only; each plugin adds its keys
(`<name>.schema.json` in each built-in feature package). This writes the schema a scene
is checked against: the default plugins' keys, or those of the plugins SCENE turns on
(a level's `game` key: its game mode's schema).
Point an editor at the file with the scene's `"$schema"`. The bundled
`assets/schema/scene.schema.json` is this command's output for the default plugins
(a test keeps it so), which the bundled scenes name.
"""

from __future__ import annotations

import argparse
import json
import sys

from ecs_tentacles.cli.arguments import output_path
from ecs_tentacles.game.rules import scene_schema
from ecs_tentacles.output.atomic import atomic_output
from ecs_tentacles.scene.load import load_scene_plugins, resolve_scene_path
from ecs_tentacles.scene.registries import plugin_entries
from ecs_tentacles.scene.schema import load_schema, schema_for


def add_parser(commands: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    parser = commands.add_parser(
        "schema",
        help="write the scene JSON Schema with the plugins' keys (for editors)",
        description="Print (or write with --out) the scene schema assembled from the core"
        " schema and the plugins' fragments: the default plugins, or those SCENE turns on.",
    )
    parser.add_argument(
        "scene",
        nargs="?",
        metavar="SCENE",
        help="scene (file or bundled name) whose plugins to add",
    )
    parser.add_argument(
        "--out",
        type=output_path(".json"),
        metavar="FILE",
        help="write it here (atomically); without it the schema goes to stdout when that is"
        " a pipe or a file, not a terminal",
    )
    parser.add_argument(
        "--allow-systems", action="store_true", help="import the plugins SCENE names from files"
    )
    parser.set_defaults(handler=handle)


def handle(args: argparse.Namespace) -> int:
    if args.scene is None:
        schema = load_schema()
    else:
        path = resolve_scene_path(args.scene)
        scene, plugins = load_scene_plugins(path, allow_systems=args.allow_systems)
        schema = scene_schema(schema_for(plugins), scene, plugin_entries(plugins))
    text = json.dumps(schema, indent=2) + "\n"
    if args.out is None:
        if sys.stdout.isatty():
            print(
                f"error: schema: {len(text) // 1024} KB of JSON is not for a terminal;"
                " write it with --out FILE.json or pipe it (ecs-tentacles schema | less)",
                file=sys.stderr,
            )
            return 2
        print(text, end="")
        return 0
    with atomic_output(args.out) as temporary:
        temporary.write_text(text, encoding="utf-8")
    print(f"schema: wrote {args.out}")
    return 0
