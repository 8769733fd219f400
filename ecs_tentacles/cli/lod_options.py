"""`--lod {on,off}` and `--focus X,Y,R`: the level-of-detail options of run, play, bake, bench.

    ecs-tentacles run crowd.json --lod off            # every creature at full physics
    ecs-tentacles bake crowd.json --seconds 4 --out t.npz --focus=2,-1,3

Reads the parsed arguments. `apply_to_scene` writes them into a loaded scene's
`physics.lod` (bakes: the take's scene hash and Ray shards see them); the commands
that build a world themselves pass `lod_choice(args)` as `World.from_scene(lod=...)`
and hand the focus to `apply_focus`. Without the options the scene's own settings hold.
"""

from __future__ import annotations

import argparse
import math
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from ecs_tentacles.world import World

Focus = tuple[float, float, float]  # x, y, radius (m)
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


def add_lod_arguments(parser: argparse.ArgumentParser) -> None:
    """`--lod` and `--focus`, shared by the commands that simulate."""
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


def lod_choice(args: argparse.Namespace) -> bool | None:
    """`World.from_scene(lod=...)` for these arguments: True, False, or None (the scene's)."""
    return None if args.lod is None else args.lod == "on"


def apply_to_scene(scene: dict[str, Any], args: argparse.Namespace) -> dict[str, Any]:
    """`scene` with `--lod` / `--focus` written into its `physics.lod` (a new dict;
    `scene` itself is left as it was)."""
    if args.lod is None and args.focus is None:
        return scene
    physics = dict(scene.get("physics") or {})
    lod = dict(physics.get("lod") or {})
    if args.lod is not None:
        lod["enabled"] = args.lod == "on"
    if args.focus is not None:
        x, y, radius = args.focus
        lod["focus"] = {"center": [x, y], "radius": radius}
    physics["lod"] = lod
    return {**scene, "physics": physics}


def apply_focus(world: World, focus: Focus | None) -> None:
    """Give a built world the `--focus` region (nothing without one)."""
    if focus is not None:
        world.lod.focus(focus[:2], focus[2])
