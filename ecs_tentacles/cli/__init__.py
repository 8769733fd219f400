"""The `ecs-tentacles` command line: `validate` and `run` (headless).

Bad input (a scene file, an argument) prints one line per problem to stderr and
exits with code 2, without a traceback.
"""

from __future__ import annotations

import argparse
import signal
import sys
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from types import FrameType

from ecs_tentacles import __version__
from ecs_tentacles.cli import bake, create, export, play, run, validate
from ecs_tentacles.export.atomic import OutputError
from ecs_tentacles.scene import load
from ecs_tentacles.scene.errors import SceneError

COMMANDS = {"validate": validate, "run": run, "play": play}
COMMANDS |= {"bake": bake, "export": export, "create": create}


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="ecs-tentacles",
        description="Tentacled creatures from JSON scenes, simulated with MuJoCo.",
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    parser.add_argument(
        "--max-scene-mb",
        type=scene_megabytes,
        default=None,
        metavar="MB",
        help=f"largest scene file read (default {load.MAX_SCENE_BYTES >> 20})",
    )
    commands = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for module in COMMANDS.values():
        module.add_parser(commands)
    return parser


class Terminated(BaseException):
    """SIGTERM or SIGHUP arrived: unwinds like Ctrl-C so partial outputs are removed."""


def _terminate(signum: int, frame: FrameType | None) -> None:
    raise Terminated(signal.Signals(signum).name)


@contextmanager
def terminate_by_exception() -> Iterator[None]:
    """While inside, SIGTERM and SIGHUP raise `Terminated` (main thread only)."""
    wanted = (signal.SIGTERM, signal.SIGHUP)
    try:
        previous = {s: signal.signal(s, _terminate) for s in wanted}
    except ValueError:  # not the main thread: leave signals alone
        previous = {}
    try:
        yield
    finally:
        for number, handler in previous.items():
            signal.signal(number, handler)


def scene_megabytes(text: str) -> float:
    """argparse type: a size in MB, > 0."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a number, got {text!r}") from None
    if not 0 < value < 1e6:
        raise argparse.ArgumentTypeError(f"must be in (0, 1000000), got {text}")
    return value


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the `ecs-tentacles` console script; returns the exit code."""
    args = build_parser().parse_args(argv)
    limit = load.MAX_SCENE_BYTES
    if args.max_scene_mb is not None:
        load.MAX_SCENE_BYTES = int(args.max_scene_mb * 1024**2)
    try:
        with terminate_by_exception():
            return _run(args)
    finally:
        load.MAX_SCENE_BYTES = limit


def _run(args: argparse.Namespace) -> int:
    try:
        return int(args.handler(args))
    except OutputError as error:
        print(f"error: {error}", file=sys.stderr)
        return 1
    except Terminated as stop:
        print(f"error: stopped by {stop}; partial outputs removed", file=sys.stderr)
        return 143
    except SceneError as error:
        for problem in error.problems:
            print(f"error: {problem}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        return 130
