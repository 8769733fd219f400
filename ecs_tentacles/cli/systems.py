"""`ecs-tentacles systems SCENE`: the frame a scene runs, as a data-flow table.

One row per system in frame order: its stage, the plugin that added it, the store
fields it reads and writes. Two systems of one stage that write the same field with
nothing ordering them are listed as warnings. Nothing is simulated.
"""

from __future__ import annotations

import argparse
import json

from ecs_tentacles.cli.world_options import CODE, parents, world_options
from ecs_tentacles.plugin import Plugin
from ecs_tentacles.scene.load import resolve_scene_path
from ecs_tentacles.world import World


def add_parser(commands: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    parser = commands.add_parser(
        "systems",
        help="print the frame's systems: stage, plugin, reads, writes",
        description="Build the scene (no simulation) and print the plugins on and every"
        " system in frame order with the stage it runs in and the fields it reads and"
        " writes; warn about unordered writers of one field.",
        parents=parents(CODE),
    )
    parser.add_argument("scene", metavar="SCENE", help="scene file or bundled scene name")
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    parser.set_defaults(handler=handle)


def handle(args: argparse.Namespace) -> int:
    path = resolve_scene_path(args.scene)
    with World.from_scene(path, world_options(args).but(threads=1)) as world:
        schedule = world.schedule
        plugins = [
            {"name": p.key, "source": _origin(p), "description": p.description}
            for p in world.plugins
        ]
        conflicts = [
            f"{first} and {second} both write {field} in stage {schedule.stage_of(first)}"
            " with nothing ordering them"
            for field, first, second in schedule.conflicts
        ]
        if args.json:
            print(json.dumps({"scene": str(path), "plugins": plugins, "systems": schedule.rows(),
                              "warnings": conflicts}))  # fmt: skip
            return 0
        print("plugins: " + ", ".join(f"{p['name']} ({p['source']})" for p in plugins))
        print(schedule.table())
        for line in conflicts:
            print(f"warning: {line}")
    return 0


def _origin(plugin: Plugin) -> str:
    """Where a plugin came from: built in, a bundled example, or its file or module."""
    if plugin.source is not None:
        return plugin.source
    # the engine's plugins are in its package; the examples in their own (`systems/`)
    return "built in" if type(plugin).__module__.startswith("ecs_tentacles.") else "bundled example"
