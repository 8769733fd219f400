"""The `ecs-tentacles` command line itself: the parser, the commands, the error rules
(`ecs_tentacles.cli` describes them)."""

from __future__ import annotations

import argparse
import signal
import sys
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from types import FrameType

from ecs_tentacles import __version__
from ecs_tentacles.cli import (
    bake,
    bench,
    create,
    crowd,
    export,
    migrate,
    play,
    run,
    schema,
    systems,
    validate,
)
from ecs_tentacles.cli.arguments import NoDisplay, OneLineParser
from ecs_tentacles.output.atomic import OutputError, release_claims
from ecs_tentacles.plugin import HookFailure
from ecs_tentacles.scene import load
from ecs_tentacles.scene.errors import SceneError
from ecs_tentacles.system import SystemFailure
from ecs_tentacles.take import TakeError

COMMANDS = {"validate": validate, "run": run, "play": play}
COMMANDS |= {"bake": bake, "export": export, "create": create}
COMMANDS |= {"crowd": crowd, "bench": bench, "systems": systems, "migrate": migrate}
COMMANDS |= {"schema": schema}


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
    release_claims()  # outputs are claimed afresh as this run's arguments are read
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
    except SceneError as error:
        for problem in error.problems:
            print(f"error: {problem}", file=sys.stderr)
        return 2
    except (TakeError, NoDisplay) as error:
        print(f"error: {error}", file=sys.stderr)
        return 2
    except OutputError as error:
        print(f"error: {error}", file=sys.stderr)
        return 1
    except SystemFailure as failure:  # a user system raised: show where in their code
        if args.debug:
            raise
        print(f"error: {failure}", file=sys.stderr)
        print(failure.user_traceback(), end="", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        _quiet_finalizers()
        print("error: interrupted (Ctrl-C); partial outputs removed", file=sys.stderr)
        return 130
    except Terminated as stop:
        _quiet_finalizers()
        print(f"error: stopped by {stop}; partial outputs removed", file=sys.stderr)
        return 143
    except SystemError as error:  # a signal's exception raised inside C code (Ray's wait)
        cause = error.__cause__ or error.__context__
        if not isinstance(cause, Terminated):
            return _failed(args, error)
        print(f"error: stopped by {cause}; partial outputs removed", file=sys.stderr)
        return 143
    except HookFailure as failure:  # a plugin hook called sys.exit: named, one line
        if args.debug:
            raise
        print(f"error: {failure}", file=sys.stderr)
        return 1
    except Exception as error:
        return _failed(args, error)
    except BaseException as error:  # SystemExit or the user's own BaseException subclass
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
