"""The `ecs-tentacles` command line: validate, run, play, bake, export, create, crowd, bench,
systems, migrate, schema, blender-addon, levels.

It speaks one way: every error is one line `error: <where>: <what>` on stderr (one per
problem for a scene), exit 2 for bad input (arguments, scenes, takes, no display),
1 for a failure at run time (a write that lost a race, a crash), 130 for Ctrl-C and
143 for SIGTERM; never a traceback unless `--debug` is given, except the user's own
code's when one of their systems raises (exit 1: the line names the system, its
plugin and the frame; nothing is written). Commands that report
print a sentence by default and one JSON object with `--json`. SIGTERM and SIGHUP
unwind like Ctrl-C, so no partial output is left behind.
"""

from __future__ import annotations

import importlib
import importlib.util
from collections.abc import Sequence


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the `ecs-tentacles` console script; returns the exit code
    (`ecs_tentacles.cli.command.main`: importing this package loads no command, so the
    plugins can import the CLI's registries, `cli.registries`, cheaply)."""
    from ecs_tentacles.cli.command import main as run

    return run(argv)


def __getattr__(name: str) -> object:
    """The command line's other names (`build_parser`, `Terminated`, ...), loaded when
    first asked for. A submodule's name is the submodule (`from ecs_tentacles.cli import
    bake_ray` asks here first: loading every command then would import the module that
    asked, half made, in a circle)."""
    if importlib.util.find_spec(f"{__name__}.{name}") is not None:
        return importlib.import_module(f"{__name__}.{name}")
    command = importlib.import_module("ecs_tentacles.cli.command")
    try:
        return getattr(command, name)
    except AttributeError:
        raise AttributeError(f"module 'ecs_tentacles.cli' has no attribute {name!r}") from None
