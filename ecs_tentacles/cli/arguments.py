"""Shared command-line pieces: the one-line parser, output-file types, the display check."""

from __future__ import annotations

import argparse
import importlib.resources
import os
import re
import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import NoReturn

from ecs_tentacles.output.atomic import OutputError, claim

# options whose value may start with "-" (`--focus -2,1,3`): argparse takes "-2,1,3" for
# an option and says "expected one argument"; such a value is joined to its option
NEGATIVE_VALUES = ("--focus", "--camera")
_NUMBER_START = re.compile(r"^-\.?\d")
# options whose value may be two words (`--camera follow NAME`): joined into one value
TWO_WORD_VALUES = {"--camera": "follow"}


def joined_negative_values(argv: Sequence[str]) -> list[str]:
    """`argv` with `--focus -2,1,3` written `--focus=-2,1,3` (a value that starts with a
    minus and a digit, after an option of `NEGATIVE_VALUES`) and `--camera follow NAME`
    written `--camera=follow NAME` (`TWO_WORD_VALUES`)."""
    out: list[str] = []
    words = list(argv)
    i = 0
    while i < len(words):
        word = words[i]
        if word == "--":  # the rest is positional
            out += words[i:]
            break
        if word in NEGATIVE_VALUES and i + 1 < len(words) and _NUMBER_START.match(words[i + 1]):
            out.append(f"{word}={words[i + 1]}")
            i += 2
            continue
        first = TWO_WORD_VALUES.get(word)
        if first is not None and i + 2 < len(words) and words[i + 1] == first:
            out.append(f"{word}={first} {words[i + 2]}")
            i += 3
            continue
        out.append(word)
        i += 1
    return out


class OneLineParser(argparse.ArgumentParser):
    """argparse, but a bad argument is one line `error: <where>: <what>` (exit 2).

    `<where>` is the argument argparse names, or the command; `--help` shows usage.
    A value starting with "-" after `--focus` is taken as its value (`NEGATIVE_VALUES`).
    """

    def parse_known_args(  # type: ignore[override]
        self, args: Sequence[str] | None = None, namespace: argparse.Namespace | None = None
    ) -> tuple[argparse.Namespace, list[str]]:
        words = sys.argv[1:] if args is None else args
        return super().parse_known_args(joined_negative_values(words), namespace)

    def error(self, message: str) -> NoReturn:
        text = " ".join(message.split())
        where = "" if text.startswith("argument ") else f"{self.prog}: "
        if "expected one argument" in text:  # its value began with "-": `--opt=-value`
            option = text.removeprefix("argument ").split(":")[0].split("/")[-1]
            text += f"; a value that starts with '-' is written {option}=VALUE"
        self.exit(2, f"error: {where}{text} (see {self.prog} --help)\n")


class NoDisplay(Exception):
    """A window was asked for on a machine without a display."""

    ADVICE = {
        "play": "no display to open a window on; use --headless (with --screenshot or --video)",
        "create": "no display to open the creator window on; use --out FILE to write the"
        " scene without a window",
    }

    @classmethod
    def advice(cls, command: str) -> str:
        return cls.ADVICE.get(command, "no display to open a window on")


def require_display(command: str) -> None:
    """Raise `NoDisplay` (one line) before pyglet tries to open a window with no display."""
    if sys.platform.startswith("linux") and not (
        os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")
    ):
        raise NoDisplay(f"{command}: {NoDisplay.advice(command)}")


def add_switch(parser: argparse.ArgumentParser, name: str, on: str, off: str) -> None:
    """`--NAME` (True, help `on`) or `--no-NAME` (False, help `off`), not both; neither:
    None (the command decides)."""
    either = parser.add_mutually_exclusive_group()
    dest = name.replace("-", "_")
    either.add_argument(
        f"--{name}", dest=dest, action="store_const", const=True, default=None, help=on
    )
    either.add_argument(f"--no-{name}", dest=dest, action="store_const", const=False, help=off)


def counted(count: int, noun: str) -> str:
    """`1 creature`, `2 creatures`, `0 goals` (nouns that take an s)."""
    return f"{count} {noun if count == 1 else noun + 's'}"


def bounded_int(minimum: int, maximum: int) -> Callable[[str], int]:
    """An argparse type: a whole number in [minimum, maximum] (one line otherwise)."""

    def check(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"must be a whole number, got {text!r}") from None
        if value < minimum:
            raise argparse.ArgumentTypeError(f"must be >= {minimum}, got {value}")
        if value > maximum:
            raise argparse.ArgumentTypeError(f"must be <= {maximum}, got {value}")
        return value

    return check


MAX_FRAMES = 10_000_000  # frames a command runs: 46 hours of simulated time at 60 fps
MAX_SEED = 2**63 - 1
MAX_THREADS = 256
frame_count = bounded_int(1, MAX_FRAMES)


def add_frames(parser: argparse.ArgumentParser, default: int, when: str = "") -> None:
    """`--frames N` (default `default`), the frames a run steps; `when` heads its help
    (`"headless: "`: only then)."""
    parser.add_argument(
        "--frames",
        type=frame_count,
        default=default,
        help=f"{when}frames to run (default {default}; a level stops sooner once its game"
        " is won or lost)",
    )


seed_int = bounded_int(0, MAX_SEED)
thread_count = bounded_int(1, MAX_THREADS)


def installed_folders() -> set[Path]:
    """The package's folders (its code and systems, bundled scenes and schemas, the example
    plugins): read-only inputs. (The repository's other assets, such as the README's
    pictures, are not.)"""
    import ecs_tentacles

    folders = {Path(ecs_tentacles.__file__).resolve().parent}
    for package in ("ecs_tentacles.assets", "ecs_tentacles_examples"):
        found = importlib.resources.files(package)
        # an editable install may give a MultiplexedPath: every folder it joins
        for root in getattr(found, "_paths", [found]):
            root = Path(str(root)).resolve()
            if package.endswith("assets"):
                folders |= {root / "scenes", root / "schema"}
            else:
                folders.add(root)
    return folders


def read_only_problem(path: Path) -> str | None:
    """Why `path` may not be written (it is inside the installed package), or None."""
    resolved = path.resolve()
    for folder in sorted(installed_folders()):
        if resolved.is_relative_to(folder):
            return f"{path} is inside the installed package ({folder}): bundled files are read-only"
    return None


def output_path(*suffixes: str) -> Callable[[str], Path]:
    """An argparse type: a file ending in one of `suffixes`, in a folder this user may
    write; the file is claimed (`atomic.claim`): if another program writes it before
    this run does, this run keeps theirs and fails."""

    def check(text: str) -> Path:
        path = Path(text)
        if path.suffix.lower() not in suffixes:
            wanted = suffixes[0] if len(suffixes) == 1 else f"one of {', '.join(suffixes)}"
            raise argparse.ArgumentTypeError(f"must end in {wanted}, got {text!r}")
        if path.is_dir():
            raise argparse.ArgumentTypeError(f"{text} is a folder")
        problem = read_only_problem(path)
        if problem:
            raise argparse.ArgumentTypeError(f"{problem}; write somewhere else")
        try:  # what the file is now: a run that finds it changed at the end keeps theirs
            claim(path)
        except OutputError as error:
            raise argparse.ArgumentTypeError(str(error).removeprefix(f"{path}: ")) from None
        return path

    return check
