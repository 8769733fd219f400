"""`ecs-tentacles crowd N --out scene.json`: write a scene of N varied creatures.

    ecs-tentacles crowd 256 --out crowd.json --seed 4 --idle 0.2

The creatures, their placement and their goals are described in
`ecs_tentacles.creator.crowd`; the same seed writes the same file.
"""

from __future__ import annotations

import argparse

import numpy as np

from ecs_tentacles.cli.arguments import output_path, seed_int
from ecs_tentacles.cli.bake import positive_float
from ecs_tentacles.cli.run import positive_int
from ecs_tentacles.creator.crowd import (
    DEFAULT_SPECIES,
    crowd_scene,
    max_creatures,
    write_crowd_scene,
)
from ecs_tentacles.output.progress import status
from ecs_tentacles.scene.construction import creature_reach
from ecs_tentacles.scene.errors import SceneError
from ecs_tentacles.terrain import presets


def crowd_size(text: str) -> int:
    """argparse type: a number of creatures, 1 to the most a scene holds."""
    value = positive_int(text)
    if value > max_creatures():
        raise argparse.ArgumentTypeError(
            f"must be <= {max_creatures()} (the most creatures a scene holds), got {value}"
        )
    return value


def fraction(text: str) -> float:
    """argparse type: a number in [0, 1]."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a number, got {text!r}") from None
    if not 0.0 <= value <= 1.0:
        raise argparse.ArgumentTypeError(f"must be in [0, 1], got {text}")
    return value


def add_crowd_options(parser: argparse.ArgumentParser) -> None:
    """--seed, --spacing, --idle, --species, --uniform, --terrain: shared by `crowd` and
    `bench --crowd`."""
    parser.add_argument("--seed", type=seed_int, default=0, help="random seed (default 0)")
    parser.add_argument(
        "--spacing",
        type=positive_float,
        default=None,
        help="grid spacing in metres (default: twice the largest creature reach + 0.4 m)",
    )
    parser.add_argument(
        "--idle",
        type=fraction,
        default=0.0,
        help="fraction of creatures with no goal (default 0)",
    )
    parser.add_argument(
        "--species",
        type=positive_int,
        default=DEFAULT_SPECIES,
        help=f"number of distinct body plans (default {DEFAULT_SPECIES})",
    )
    parser.add_argument(
        "--uniform",
        action="store_true",
        help="every creature the default 8 x 10 octopus (one morphology; behaviour still varies)",
    )
    parser.add_argument(
        "--terrain",
        choices=presets.NAMES,
        default="flat",
        help="the ground: flat (the plane, default) or rocky (a noise heightfield under the"
        " whole crowd with rocks between the creatures)",
    )


def crowd_from_args(n: int, args: argparse.Namespace) -> dict[str, object]:
    """The crowd scene of `n` creatures the options ask for; SceneError names a bad option."""
    try:
        scene = crowd_scene(
            n, args.seed, args.spacing, idle=args.idle, species=args.species, uniform=args.uniform
        )
    except ValueError as error:  # only --spacing can be wrong once argparse has checked
        raise SceneError([f"--{error}"]) from None
    if args.terrain == "rocky":
        creatures = scene["creatures"]
        positions = np.array([c["position"] for c in creatures], dtype=np.float64)
        reach = max(creature_reach(c) for c in creatures)
        scene["terrain"] = presets.rocky(positions, reach, args.seed)
    return scene


def add_parser(commands: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    parser = commands.add_parser(
        "crowd",
        help="write a scene of N varied creatures whose paths cross",
        description=(
            "Write a scene of N varied creatures (3-8 tentacles, varied sizes, some with fur)"
            " on a jittered grid, each crawling to the far side of the crowd's centre."
        ),
    )
    parser.add_argument(
        "n", type=crowd_size, metavar="N", help=f"number of creatures (1 to {max_creatures()})"
    )
    parser.add_argument(
        "--out", type=output_path(".json"), required=True, help="scene file to write (.json)"
    )
    add_crowd_options(parser)
    parser.set_defaults(handler=handle)


def handle(args: argparse.Namespace) -> int:
    with status(f"crowd: making and checking {args.n} creatures"):
        scene = crowd_from_args(args.n, args)
        write_crowd_scene(scene, args.out)
    creatures = scene["creatures"]
    assert isinstance(creatures, list)  # (`crowd_scene`'s creature entries)
    furry = sum("fur" in c for c in creatures)
    idle = sum("goals" not in c for c in creatures)
    print(f"{args.out}: {len(creatures)} creatures ({furry} with fur, {idle} idle)")
    return 0
