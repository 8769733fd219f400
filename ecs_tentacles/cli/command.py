"""The `ecs-tentacles` command line itself: the parser, the commands, the error rules
(`ecs_tentacles.cli` describes them)."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence

from ecs_tentacles import __version__, stops
from ecs_tentacles.cli import (
    bake,
    bench,
    blender_addon,
    create,
    crowd,
    export,
    levels,
    migrate,
    play,
    run,
    schema,
    systems,
    validate,
)
from ecs_tentacles.cli.arguments import NoDisplay, OneLineParser
from ecs_tentacles.export.glb import GlbTooLarge
from ecs_tentacles.output.atomic import OutputError, claimed_outputs, release_claims
from ecs_tentacles.plugin import HookFailure
from ecs_tentacles.scene import load
from ecs_tentacles.scene.errors import SceneError
from ecs_tentacles.stops import Terminated, stops_by_exception
from ecs_tentacles.system import SystemFailure
from ecs_tentacles.take import TakeError

COMMANDS = {"validate": validate, "run": run, "play": play}
COMMANDS |= {"bake": bake, "export": export, "create": create}
COMMANDS |= {"crowd": crowd, "bench": bench, "systems": systems, "migrate": migrate}
COMMANDS |= {"schema": schema, "blender-addon": blender_addon, "levels": levels}


def build_parser() -> argparse.ArgumentParser:
    parser = OneLineParser(
        prog="ecs-tentacles",
        description="Tentacled creatures from JSON scenes, simulated with MuJoCo.",
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    _add_shared_options(parser, None)
    commands = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for module in COMMANDS.values():
        module.add_parser(commands)
    for command in commands.choices.values():  # also after the command: `run octopus --debug`
        _add_shared_options(command, argparse.SUPPRESS)
    return parser


def _add_shared_options(parser: argparse.ArgumentParser, default: object) -> None:
    """--max-scene-mb and --debug; a command's copies default to SUPPRESS, so they only
    set what is given after the command and leave the top-level value otherwise."""
    group = parser.add_argument_group("options of every command")
    group.add_argument(
        "--max-scene-mb",
        type=scene_megabytes,
        default=default,
        metavar="MB",
        help=f"largest scene file read (default {load.MAX_SCENE_BYTES >> 20})",
    )
    debug_default = False if default is None else default
    group.add_argument(
        "--debug", action="store_true", default=debug_default, help="show tracebacks of failures"
    )


terminate_by_exception = stops_by_exception  # (its name before Ctrl-C went there too)


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
    release_claims()  # outputs are claimed afresh as this run's arguments are read
    stops.taken()  # and no stop of an earlier command (in this process) is remembered
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
    except (KeyboardInterrupt, Terminated) as stop:
        return _stopped(stop)
    except Exception as error:
        arrived = stops.received()  # a stop inside C code can surface as another exception
        if arrived is not None:  # (pybind11's TypeError, Ray's SystemError): report the stop
            return _stopped(arrived)
        return _failure(args, error)
    except BaseException as error:  # SystemExit or the user's own BaseException subclass
        return _failed(args, error)


def _stopped(stop: BaseException) -> int:
    """Ctrl-C (130) or SIGTERM / SIGHUP (143): one line; the stop is reported. A stop
    that came once every output of the command was written stopped nothing: exit 0, and
    a note says the outputs are kept."""
    stops.taken()
    _quiet_finalizers()
    written, unwritten = claimed_outputs()
    names = ", ".join(map(str, written))
    what = "Ctrl-C" if isinstance(stop, KeyboardInterrupt) else str(stop)
    if written and not unwritten:
        print(f"note: {what} came once every output was written: kept {names}", file=sys.stderr)
        return 0
    kept = f"; kept {names}, written whole" if written else ""
    if isinstance(stop, KeyboardInterrupt):
        print(f"error: interrupted (Ctrl-C); partial outputs removed{kept}", file=sys.stderr)
        return 130
    print(f"error: stopped by {stop}; partial outputs removed{kept}", file=sys.stderr)
    return 143


def _failure(args: argparse.Namespace, error: Exception) -> int:
    """The exit code and line of a command that raised `error` (no stop arrived)."""
    if isinstance(error, SceneError):
        for problem in error.problems:
            print(f"error: {problem}", file=sys.stderr)
        return 2
    if isinstance(error, (TakeError, NoDisplay, GlbTooLarge)):
        print(f"error: {error}", file=sys.stderr)
        return 2
    if isinstance(error, OutputError):
        print(f"error: {error}", file=sys.stderr)
        return 1
    if isinstance(error, SystemFailure):  # a user system raised: show where in their code
        if args.debug:
            raise error
        print(f"error: {error}", file=sys.stderr)
        print(error.user_traceback(), end="", file=sys.stderr)
        return 1
    if isinstance(error, HookFailure):  # a plugin hook called sys.exit: named, one line
        if args.debug:
            raise error
        print(f"error: {error}", file=sys.stderr)
        return 1
    return _failed(args, error)


def _quiet_finalizers() -> None:
    """A run stopped by a signal ends in one line: objects the signal left half built
    (numba's compiler, stopped mid-compile: "Exception ignored in OutputString.__del__")
    are freed with the stopped frames, and their finalizers' errors are not news."""
    sys.unraisablehook = lambda unraisable: None


def _failed(args: argparse.Namespace, error: BaseException) -> int:
    """An unexpected failure: one line (the traceback with --debug)."""
    if args.debug:
        raise error
    if type(error).__name__ == "NoSuchDisplayException":  # pyglet's, from any platform
        print(f"error: {args.command}: {NoDisplay.advice(args.command)}", file=sys.stderr)
        return 2
    text = " ".join(str(error).split()) or "no details"
    print(
        f"error: {args.command}: {type(error).__name__}: {text} (--debug shows where)",
        file=sys.stderr,
    )
    return 1
