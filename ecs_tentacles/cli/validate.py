"""`ecs-tentacles validate SCENE...`: check scene files without building anything."""

from __future__ import annotations

import argparse
import sys

from ecs_tentacles.scene.errors import SceneError
from ecs_tentacles.scene.load import load_scene, resolve_scene_path


def add_parser(commands: argparse._SubParsersAction) -> None:
    parser = commands.add_parser(
        "validate",
        help="check scene files against the schema (exit 0 if all are valid, 2 if not)",
        description="Check scene files; print one line per problem with its JSON path.",
    )
    parser.add_argument(
        "scenes", nargs="+", metavar="SCENE", help="scene file or bundled scene name"
    )
    parser.set_defaults(handler=handle)


def handle(args: argparse.Namespace) -> int:
    failed = False
    for scene in args.scenes:
        path = resolve_scene_path(scene)
        try:
            data = load_scene(path)
        except SceneError as error:
            failed = True
            for problem in error.problems:
                print(f"error: {problem}", file=sys.stderr)
            continue
        creatures = data["creatures"]
        tentacles = sum(c["tentacles"]["count"] for c in creatures)
        print(f"{path}: ok ({len(creatures)} creatures, {tentacles} tentacles)")
    return 2 if failed else 0
