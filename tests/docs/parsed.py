"""What a `<!-- parsed, not run: why -->` block of the docs is checked for, without running it
(and a `<!-- slow: why -->` block, where the slow tier does not run: tests/docs/slow.py).

Each `ecs-tentacles ...` line (and each command of a `&&` chain) is parsed by the
command line's own parser (`ecs_tentacles.cli.build_parser`), and each `python tools/X.py
...` line by that tool's (`build_parser()`): a misspelt or renamed option, a bad value,
a missing output folder fail as they would for the reader. Then what the line reads must
be there: a scene or take (`scene`, `scenes`, `take`, `--from`, a bot's levels) is a
bundled scene's name, a file the page made (a `file:` block, a command run before it) or
an output of an earlier line of the page (`--out`, `--screenshot`, `--video`,
`--render`); a repository path (`assets/...`, `tools/...`) exists. `mkdir -p DIR` makes
the folder (in the page's scratch folder). Commands that are not this project's are
named by kind in `OTHER_COMMANDS`, with what checks them instead (of those, `pip install
-e '.[x]'` has its extras checked against pyproject.toml); any other command fails the
test.
"""

from __future__ import annotations

import argparse
import contextlib
import functools
import importlib.util
import io
import re
import shlex
import sys
import tomllib
from collections.abc import Callable, Iterator
from pathlib import Path
from types import ModuleType

from ecs_tentacles.cli import build_parser
from ecs_tentacles.output.atomic import release_claims
from ecs_tentacles.scene.errors import SceneError
from ecs_tentacles.scene.load import bundled_scene

ROOT = Path(__file__).resolve().parents[2]
# commands that are not this project's, by kind (their first words): not checked here
OTHER_COMMANDS = {
    "python3 -m venv": "makes a virtual environment; the slow tier runs the install blocks",
    ".": "the shell's `source` (activates the virtual environment)",
    "pip install": "installs the package; the slow tier runs the install blocks",
    "pytest": "the whole suite; the slow tier runs the block, CI (.ci/run) the same suite",
    "mkdocs build": "the docs build; the slow tier runs the block, CI (.ci/run) the same build",
    "ray start": "Ray's own command; the slow tier starts a head and a second node on one machine",
    "blender": "Blender's own command; the slow tier runs its extension command in bpy",
}
READS = ("scene", "scenes", "take", "source", "levels")  # what a line reads
WRITES = ("out", "screenshot", "video", "render")  # what a line writes
REPOSITORY = ("assets/", "tools/", "tests/", "docs/")  # paths in the repository
EXTRAS = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["optional-dependencies"]


def kind(argv: list[str]) -> str | None:
    """The kind in `OTHER_COMMANDS` that `argv` is, or None."""
    for name in OTHER_COMMANDS:
        words = name.split()
        if argv[: len(words)] == words:
            return name
    return None


def chained(argv: list[str]) -> Iterator[list[str]]:
    """The commands of a `a && b && c` line."""
    command: list[str] = []
    for word in [*argv, "&&"]:
        if word == "&&":
            if command:
                yield command
            command = []
        else:
            command.append(word)


@functools.cache
def tool(name: str) -> ModuleType:
    """`tools/<name>.py` imported (not run), with `tools/` on the import path."""
    folder = str(ROOT / "tools")
    if folder not in sys.path:
        sys.path.append(folder)
    spec = importlib.util.spec_from_file_location(f"docs_{name}", ROOT / "tools" / f"{name}.py")
    assert spec and spec.loader
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def exact(parser: argparse.ArgumentParser) -> argparse.ArgumentParser:
    """`parser` and its subcommands' parsers taking options only as spelt in full (argparse
    takes `--out` for `--output`: a renamed option would still parse)."""
    parser.allow_abbrev = False
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for command in action.choices.values():
                exact(command)
    return parser


def parse(parser: argparse.ArgumentParser, argv: list[str], where: str) -> argparse.Namespace:
    """`argv` parsed by `parser`, options spelt in full; what the parser said if it
    refused them."""
    parser = exact(parser)
    said = io.StringIO()
    try:
        with contextlib.redirect_stderr(said):
            return parser.parse_args(argv)
    except SystemExit:
        raise AssertionError(f"{where}: {said.getvalue().strip().splitlines()[-1]}") from None
    finally:
        release_claims()  # an output type claims its file: this run writes nothing


def values(args: argparse.Namespace, names: tuple[str, ...]) -> list[str]:
    found: list[str] = []
    for name in names:
        value = getattr(args, name, None)
        if value is not None:
            found += [str(v) for v in value] if isinstance(value, list) else [str(value)]
    return found


def check_line(argv: list[str], folder: Path, made: set[str], where: str) -> None:
    """One command of a parsed block: parsed, what it reads found, what it writes kept
    in `made` (paths as written, relative to the page's scratch `folder`)."""
    if argv[:2] == ["mkdir", "-p"]:
        for name in argv[2:]:
            (folder / name).mkdir(parents=True, exist_ok=True)
        return
    if argv[0] == "ecs-tentacles":
        parser: Callable[[], argparse.ArgumentParser] = build_parser
        words = argv[1:]
    elif argv[0] == "python" and len(argv) > 1 and argv[1].startswith("tools/"):
        assert (ROOT / argv[1]).is_file(), f"{where}: no {argv[1]} in the repository"
        parser = tool(Path(argv[1]).stem).build_parser
        words = argv[2:]
    else:
        assert kind(argv), (
            f"{where}: `{shlex.join(argv)}` is neither this project's command nor a kind"
            " tests/docs/parsed.py names (OTHER_COMMANDS)"
        )
        if kind(argv) == "pip install":  # the extras it names are the package's
            for extras in re.findall(r"^\.\[(.+)\]$", argv[-1]):
                unknown = set(extras.split(",")) - set(EXTRAS)
                assert not unknown, f"{where}: no extra {sorted(unknown)} in pyproject.toml"
        return
    with contextlib.chdir(folder):
        args = parse(parser(), words, where)
        for name in values(args, READS):
            there = Path(name).exists() or name in made
            assert there or is_bundled(name), (
                f"{where}: {name!r} is neither a bundled scene, nor a file the page made,"
                " nor an output of a line before it"
            )
    for word in words:
        path = word.split("=", 1)[-1]
        if path.startswith(REPOSITORY):
            assert (ROOT / path).exists(), f"{where}: no {path} in the repository"
    made.update(values(args, WRITES))


def is_bundled(name: str) -> bool:
    try:
        bundled_scene(name)
    except SceneError:
        return False
    return True


def check_block(lines: list[list[str]], folder: Path, made: set[str], where: str) -> None:
    """Every command of a parsed block's lines (see the module's docstring)."""
    for argv in lines:
        for command in chained(argv):
            check_line(command, folder, made, where)
