"""`ecs-tentacles validate SCENE...`: check scene files as `run` does before it simulates.

Every check a run makes before its first frame runs here: the schema and the scene's
rules, then the world is built as far as a run builds it before compiling the physics
(each plugin's resources, the files they read, such as the terrain's height image and
meshes, its build hooks, its systems), and thrown away.
"""

from __future__ import annotations

import argparse
import json
import pathlib
import sys
from collections.abc import Mapping
from typing import TYPE_CHECKING, TypedDict

from ecs_tentacles.cli.arguments import counted
from ecs_tentacles.cli.world_options import CODE, parents
from ecs_tentacles.output.progress import status
from ecs_tentacles.scene.errors import SceneError
from ecs_tentacles.scene.load import resolve_scene_path

if TYPE_CHECKING:
    from ecs_tentacles.plugin import Plugin


def add_parser(commands: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    parser = commands.add_parser(
        "validate",
        help="check scene files against the schema (exit 0 if all are valid, 2 if not)",
        description="Check scene files as run does before it simulates (the files a scene"
        " names included); print one line per problem with its JSON path, and the systems a"
        " scene asks for (run, bake and play import them only with --allow-systems).",
        parents=parents(CODE),
    )
    parser.add_argument(
        "scenes", nargs="+", metavar="SCENE", help="scene file or bundled scene name"
    )
    parser.add_argument(
        "--json",
        action="store_true",
        help='one JSON object per scene ({"ok": false, "problems": [...]} for a bad one)',
    )
    parser.set_defaults(handler=handle)


class Summary(TypedDict):
    """What `validate` reports of a valid scene (--json prints it as it is)."""

    scene: str
    ok: bool
    creatures: int
    tentacles: int
    systems: list[str]  # the systems it asks for ("package.module:ClassName")
    plugins: list[str]  # the plugins it runs


def summary(path: str, data: Mapping[str, object], plugins: list[str]) -> Summary:
    """What a valid scene holds, for the sentence and for --json."""
    creatures, systems = data["creatures"], data.get("systems", [])
    assert isinstance(creatures, list) and isinstance(systems, list)  # as validated
    return {
        "scene": path,
        "ok": True,
        "creatures": len(creatures),
        "tentacles": sum(c["tentacles"]["count"] for c in creatures),
        "systems": list(systems),
        "plugins": plugins,  # the plugins it runs
    }


def sentence(report: Summary) -> str:
    """`octopus.json: ok (1 creature, 8 tentacles)`, plus the systems it asks for."""
    text = (
        f"{report['scene']}: ok ({counted(report['creatures'], 'creature')},"
        f" {counted(report['tentacles'], 'tentacle')})"
    )
    if report["systems"]:
        text += (
            f"; asks to run systems {', '.join(report['systems'])}"
            " (run, bake and play need --allow-systems)"
        )
    return text


def checked(path: pathlib.Path, allow_systems: bool) -> tuple[Mapping[str, object], list[Plugin]]:
    """The scene at `path`, completed, and its plugins, once every check a run makes
    before simulating has passed (SceneError otherwise, each line led by the path)."""
    from ecs_tentacles.creatures.loading import load_world
    from ecs_tentacles.options import WorldOptions
    from ecs_tentacles.world import World

    try:
        options = WorldOptions(allow_systems=allow_systems)
        world = load_world(World, path, options, checks_only=True)
    except SceneError as error:
        named = f"{path}:"  # `path: ...` or, located in the text, `path:5:3: ...`
        lines = [p if p.startswith(named) else f"{named} {p}" for p in error.problems]
        raise SceneError(lines) from None
    try:
        assert world.scene is not None
        return world.scene, list(world.plugins)
    finally:
        world.close()


def handle(args: argparse.Namespace) -> int:
    from ecs_tentacles.terrain.meshes import one_worker

    with one_worker():  # one mesh worker for all the scenes, not one a scene
        return _validate_each(args)


def _validate_each(args: argparse.Namespace) -> int:
    failed = False
    for scene in args.scenes:
        try:
            path = resolve_scene_path(scene)
            with status(f"validate: checking {path}"):
                data, plugins = checked(path, args.allow_systems)
        except SceneError as error:
            failed = True
            for problem in error.problems:
                print(f"error: {problem}", file=sys.stderr)
            if args.json:
                print(json.dumps({"scene": scene, "ok": False, "problems": error.problems}))
            continue
        report = summary(str(path), data, [plugin.key for plugin in plugins])
        print(json.dumps(report) if args.json else sentence(report))
    return 2 if failed else 0
