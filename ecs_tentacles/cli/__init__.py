"""The `ecs-tentacles` command line: `validate` and `run` (headless).

Bad input (a scene file, an argument) prints one line per problem to stderr and
exits with code 2, without a traceback.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence

from ecs_tentacles import __version__
from ecs_tentacles.cli import bake, bench, create, crowd, export, play, run, validate
from ecs_tentacles.scene.errors import SceneError

COMMANDS = {"validate": validate, "run": run, "play": play}
COMMANDS |= {"bake": bake, "export": export, "create": create}
COMMANDS |= {"crowd": crowd, "bench": bench}


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="ecs-tentacles",
        description="Tentacled creatures from JSON scenes, simulated with MuJoCo.",
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    commands = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for module in COMMANDS.values():
        module.add_parser(commands)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the `ecs-tentacles` console script; returns the exit code."""
    args = build_parser().parse_args(argv)
    try:
        return int(args.handler(args))
    except SceneError as error:
        for problem in error.problems:
            print(f"error: {problem}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        return 130
