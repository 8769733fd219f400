"""`ecs-tentacles levels`: the game's levels, in order, with par times, best times and stars.

    ecs-tentacles levels           # one line a level: open or locked, stars, best and par
    ecs-tentacles levels --json    # one JSON object a level (`ecs_tentacles.herding.levels.Level`)

Reads the bundled scenes' `game` keys and the best-times file; writes nothing. The
listing is the game layer's (`ecs_tentacles.herding.levels`), which sits above the
command line (it fills the command line's registries): it is imported by name when the
command runs, as plugins are (`ecs_tentacles.scene.plugins`), never at import.
"""

from __future__ import annotations

import argparse
import importlib
import json
from collections.abc import Callable
from typing import Protocol

LISTING = "ecs_tentacles.herding.levels"  # levels(), stars_text(): the game's listing


def add_parser(commands: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    parser = commands.add_parser(
        "levels",
        help="list the game's levels: open or locked, par time, best time, stars",
        description="List the bundled game levels in the order they are played, each with"
        " its goal, time limit, par time, your best time and stars (3: within par, 2:"
        " within 1.5x par, 1: won), and whether it is open (the first level of a mode is;"
        " each next one opens when the one before it is won). Play one with"
        " `ecs-tentacles play SCENE`.",
    )
    parser.add_argument("--json", action="store_true", help="one JSON object per level")
    parser.set_defaults(handler=handle)


class LevelLine(Protocol):
    """What a line of the listing reads of a level (the game's `Level`)."""

    @property
    def scene(self) -> str: ...
    @property
    def title(self) -> str: ...
    @property
    def mode(self) -> str: ...
    @property
    def creatures(self) -> int: ...
    @property
    def need(self) -> int: ...
    @property
    def seconds(self) -> float: ...
    @property
    def par(self) -> float: ...
    @property
    def best(self) -> float | None: ...
    @property
    def stars(self) -> int: ...
    @property
    def unlocked(self) -> bool: ...


def sentence(level: LevelLine, stars_text: Callable[[int], str]) -> str:
    best = f"best {level.best:.1f} s" if level.best is not None else "not won yet"
    lock = "" if level.unlocked else "  (locked: win the one before)"
    goal = f" {level.need} of {level.creatures}" if level.need else ""
    return (
        f"{level.scene:<20} {stars_text(level.stars)}  {level.title}: {level.mode},{goal}"
        f" in {level.seconds:.0f} s, par {level.par:.0f} s, {best}{lock}"
    )


def handle(args: argparse.Namespace) -> int:
    listing = importlib.import_module(LISTING)
    for level in listing.levels():
        print(json.dumps(level.as_dict()) if args.json else sentence(level, listing.stars_text))
    return 0
