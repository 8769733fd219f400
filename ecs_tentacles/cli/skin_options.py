"""Command-line options of skinned export, shared by `bake` and `export`."""

from __future__ import annotations

import argparse

from ecs_tentacles.cli.arguments import bounded_int
from ecs_tentacles.export.skinned import Skin
from ecs_tentacles.skin.mesh import MAX_RINGS_PER_LINK, MAX_SIDES, Detail
from ecs_tentacles.skin.rig import KEY_MODES, Keys

FLAGS = {
    "rings_per_link": "--rings-per-link",
    "sides": "--sides",
    "keys": "--keys",
    "key tolerance": "--key-tolerance",
}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """`--rigid`, `--keys`, `--key-tolerance`, `--rings-per-link`, `--sides`, `--sucker-discs`,
    `--locators`."""
    group = parser.add_argument_group(
        "skinned creatures (USD and glTF; the default)",
        "one mesh per creature on a joint skeleton with rotation keys",
    )
    group.add_argument(
        "--rigid",
        action="store_true",
        help="write one rigid capsule per body instead (exact world poses, no skeleton)",
    )
    group.add_argument(
        "--keys", choices=KEY_MODES, default="all", help="every frame, or only the keys needed"
    )
    group.add_argument(
        "--key-tolerance",
        type=float,
        default=0.5,
        metavar="DEG",
        help="with --keys reduced: the largest rotation error kept (degrees, default 0.5)",
    )
    group.add_argument(
        "--rings-per-link",
        type=bounded_int(1, MAX_RINGS_PER_LINK),
        default=4,
        help="mesh rings per link",
    )
    group.add_argument(
        "--sides", type=bounded_int(4, MAX_SIDES), default=12, help="mesh sides (a multiple of 4)"
    )
    group.add_argument("--sucker-discs", action="store_true", help="sucker discs underneath")
    group.add_argument(
        "--locators",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="suckers and goals as locators (USD Xforms, glTF nodes; empties in Blender):"
        " off by default for skinned creatures, on for --rigid",
    )


def skin_options(args: argparse.Namespace) -> Skin | None:
    """The Skin to write, or None for the rigid form; ValueError (one line) when bad."""
    if args.rigid:
        return None
    try:
        detail = Detail(args.rings_per_link, args.sides, suckers=args.sucker_discs)
        return Skin(detail=detail, keys=Keys(args.keys, args.key_tolerance))
    except ValueError as error:
        field, _, problem = str(error).partition(": ")
        raise ValueError(f"argument {FLAGS.get(field, field)}: {problem}") from None
