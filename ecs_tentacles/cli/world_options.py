"""The options of every command that builds a world, declared once as parent parsers,
and the `WorldOptions` they make (`ecs_tentacles.options`).

    ecs-tentacles run crowd.json --seed 3 --lod off        # every creature at full physics
    ecs-tentacles bake crowd.json --seconds 4 --out t.npz --focus=2,-1,3

* `SEED`: `--seed N` over the scene's seed;
* `CODE`: `--allow-systems`, importing the code a scene names;
* `PHYSICS`: `--threads N`, `--lod {on,off}` and `--focus X,Y,R`.

A command lists the ones it takes (`commands.add_parser("run", parents=parents(SEED,
CODE, PHYSICS))`) and hands `world_options(args)` on: to `World.from_scene`, the
sandbox, a bake (which writes `lod` and `focus` into its scene: the take's scene hash
and the shards see them, `WorldOptions.scene_with_lod`). Reads the parsed arguments.
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable

from ecs_tentacles.cli.arguments import seed_int, thread_count
from ecs_tentacles.options import Focus, WorldOptions

MAX_RADIUS = 100000.0  # the schema's `physics.lod.focus.radius` maximum


def focus_region(text: str) -> Focus:
    """argparse type: `X,Y,R` in metres, a circle on the ground (R >= 0)."""
    parts = text.split(",")
    try:
        values = [float(part) for part in parts]
    except ValueError:
        values = []
    if len(parts) != 3 or len(values) != 3 or not all(map(math.isfinite, values)):
        raise argparse.ArgumentTypeError(f"must be X,Y,R (three numbers, metres), got {text!r}")
    x, y, radius = values
    if not 0.0 <= radius <= MAX_RADIUS:
        raise argparse.ArgumentTypeError(f"radius must be in [0, {MAX_RADIUS:g}] m, got {text!r}")
    return x, y, radius


def _seed(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--seed", type=seed_int, default=None, help="override the scene's seed")


def _code(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--allow-systems",
        action="store_true",
        help="import and run the code the scene names (plugins from files or modules, its systems)",
    )


def _physics(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--threads",
        type=thread_count,
        default=None,
        help="threads that step the physics (default: one per core); results are the same",
    )
    parser.add_argument(
        "--lod",
        choices=("on", "off"),
        default=None,
        help="level of detail for crowds (default: the scene's physics.lod.enabled);"
        " off runs every creature at full physics",
    )
    parser.add_argument(
        "--focus",
        type=focus_region,
        default=None,
        metavar="X,Y,R",
        help="creatures within R m of (X, Y) always run full physics (--focus -2,1,3"
        " and --focus=-2,1,3 both work)",
    )


Options = Callable[[argparse.ArgumentParser], None]
SEED: Options = _seed
CODE: Options = _code
PHYSICS: Options = _physics


def parents(*kinds: Options) -> list[argparse.ArgumentParser]:
    """Parent parsers (`add_parser(..., parents=...)`) holding the options `kinds`."""
    made = []
    for add in kinds:
        parent = argparse.ArgumentParser(add_help=False)
        add(parent)
        made.append(parent)
    return made


def world_options(args: argparse.Namespace) -> WorldOptions:
    """The `WorldOptions` of parsed arguments; an option the command does not take keeps
    its default (the scene's)."""
    lod = getattr(args, "lod", None)
    return WorldOptions(
        seed=getattr(args, "seed", None),
        allow_systems=bool(getattr(args, "allow_systems", False)),
        threads=getattr(args, "threads", None),
        lod=None if lod is None else lod == "on",
        focus=getattr(args, "focus", None),
    )
