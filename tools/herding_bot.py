"""The herding bot plays the bundled levels headless and reports how it did.

    python tools/herding_bot.py                      # every bundled level
    python tools/herding_bot.py herding_1_field      # one (a bundled name or a file)
    python tools/herding_bot.py --json               # one JSON object per level

For each level: won or lost, creatures penned of those needed, game seconds, and the
median frame's step time (physics and every system) with its real-time factor, the
figure that says whether the level plays at interactive rates on this machine. The bot
is `ecs_tentacles.herding.play.Bot`: one creature at a time, the one nearest the gate,
pushed from behind to the gate and through it. It plays the same game every time.
"""

from __future__ import annotations

import argparse
import json
import sys

from ecs_tentacles.herding.play import Bot, play
from ecs_tentacles.scene.load import resolve_scene_path
from ecs_tentacles.world import World

LEVELS = ("herding_1_field", "herding_2_shore", "herding_3_maze")


def build_parser() -> argparse.ArgumentParser:
    """The tool's arguments (the docs tests parse the handbook's lines with it)."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("levels", nargs="*", default=list(LEVELS), metavar="LEVEL")
    parser.add_argument("--json", action="store_true", help="one JSON object per level")
    return parser


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    for name in args.levels:
        with World.from_scene(resolve_scene_path(name)) as world:
            creatures = world.creatures.count
            result = play(world, Bot())
        result.pop("log")
        result.pop("runs")
        result["creatures"] = creatures
        if args.json:
            print(json.dumps({"scene": name, **result}), flush=True)
        else:
            print(
                f"{result['level']}: {result['outcome']}, {result['penned']} of "
                f"{result['need']} penned in {result['seconds']:.1f} s ({creatures} creatures;"
                f" a frame {result['frame_ms']:.1f} ms, {result['realtime_factor']}x real time;"
                f" {result['wall_s']:.0f} s wall)",
                flush=True,
            )
    return 0


if __name__ == "__main__":
    sys.exit(main())
