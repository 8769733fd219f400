"""The race bot runs the bundled race levels headless and reports how it did.

    python tools/race_bot.py                     # both race levels
    python tools/race_bot.py race_1_rock         # one (a bundled name or a file)
    python tools/race_bot.py --json              # one JSON object per level
    python tools/race_bot.py --careless          # the careless player: straight at the flag

The bot plays as a player who can see the rocks: at the start it plans a route for its
runner from where it stands to the flag round the obstacles (the locomotion plugin's
cost grid, `CostGrid.route`: what a creature with `navigation` on would follow) and
gives it as the runner's path (a click, then shift+clicks); if the runner ever has no
path left short of the flag, it plans again from where it is. The careless player
clicks the flag and nothing else. For each level: won or lost, who took the flag, the
game seconds and the time left, and the real-time factor of the race.
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from ecs_tentacles.ground import ground_of
from ecs_tentacles.locomotion.navigation import CostGrid
from ecs_tentacles.race.game import RaceGame
from ecs_tentacles.race.play import play
from ecs_tentacles.scene.load import resolve_scene_path
from ecs_tentacles.world import World

if TYPE_CHECKING:
    from ecs_tentacles.host import Host

LEVELS = ("race_1_rock", "race_2_wall")
REACH = 0.45  # metres a small creature's tentacles reach beyond its mantle


def runner_xy(world: Host, race: RaceGame) -> np.ndarray:
    creatures = world.creatures
    row = int(np.flatnonzero(creatures.entity == race.runner)[0])
    return np.asarray(world.transforms.pos[creatures.mantle_row[row], :2], dtype=np.float64)


class RouteBot:
    """Plans a route round the obstacles to the flag and gives it as the runner's path."""

    def __init__(self) -> None:
        self.planned = False

    def decide(self, world: Host, race: RaceGame) -> Sequence[Sequence[float]] | None:
        if self.planned and race.state.path:
            return None  # on its way
        self.planned = True
        start = runner_xy(world, race)
        grid = CostGrid.of(ground_of(world), REACH, np.vstack([start, race.flag]))
        route = None if grid is None else grid.route(start, race.flag)
        points = [race.flag] if route is None else list(route)
        return [(float(x), float(y)) for x, y in points]


class Careless:
    """Clicks the flag once and waits."""

    def __init__(self) -> None:
        self.clicked = False

    def decide(self, world: Host, race: RaceGame) -> Sequence[Sequence[float]] | None:
        if self.clicked:
            return None
        self.clicked = True
        return [(float(race.flag[0]), float(race.flag[1]))]


def run_level(name: str, careless: bool = False) -> dict[str, Any]:
    """Play one level with the bot (or the careless player); the race's result."""
    with World.from_scene(resolve_scene_path(name)) as world:
        result = play(world, Careless() if careless else RouteBot())
        result["real_time_factor"] = round(world.time / max(result["wall_s"], 1e-9), 2)
    result["scene"] = name
    return result


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("levels", nargs="*", default=list(LEVELS), metavar="LEVEL")
    parser.add_argument("--json", action="store_true", help="one JSON object per level")
    parser.add_argument("--careless", action="store_true", help="click the flag, nothing else")
    args = parser.parse_args(argv)
    for name in args.levels:
        result = run_level(name, args.careless)
        result.pop("log")
        if args.json:
            print(json.dumps(result), flush=True)
            continue
        who = result["winner"] or "nobody (time)"
        print(
            f"{result['level']}: {result['outcome']}, {who} took the flag at"
            f" {result['seconds']:.1f} s ({result['left']:.1f} s left;"
            f" {result['real_time_factor']}x real time, {result['wall_s']:.0f} s wall)",
            flush=True,
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
