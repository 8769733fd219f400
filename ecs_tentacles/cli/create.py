"""`ecs-tentacles create ... --out scene.json`: the creature creator, for scripts.

The same steps as the creator window (`ecs_tentacles.creator.CreatureDesign`):
uniform settings ("Build creature"), then per-tentacle changes, then "Export":

    ecs-tentacles create --tentacles 6 --links 10 --end-scale 0.4 \\
        --tentacle 2:links=12,link_length=0.09 --out squid.json

`--from SCENE` starts from a scene's creature instead of the defaults. Without
`--out` (or with `--window`) the creator window opens with the same settings
applied; its Export button writes `--out`, or `<name>.json`.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from ecs_tentacles.cli.arguments import output_path, require_display
from ecs_tentacles.cli.bake import positive_float
from ecs_tentacles.cli.run import positive_int
from ecs_tentacles.creator import SHAPE_KEYS, CreatureDesign, DesignError

# design field -> the option that sets it
OPTIONS = {
    "name": "--name",
    "creature": "--creature",
    "mantle_radius": "--mantle-radius",
    "mantle_height": "--mantle-height",
    "count": "--tentacles",
    "links": "--links",
    "link_length": "--link-length",
    "link_radius": "--link-radius",
    "end_scale": "--end-scale",
}


json_file = output_path(".json")  # a .json output path in an existing folder


def tentacle_edit(text: str) -> tuple[int, dict[str, float]]:
    """`K:key=value[,key=value]` with keys links, link_length, link_radius, end_scale."""
    index, colon, rest = text.partition(":")
    if not colon or not index.strip().isdigit() or not rest:
        raise argparse.ArgumentTypeError(f"must look like 2:links=12,end_scale=0.5, got {text!r}")
    changes: dict[str, float] = {}
    for item in rest.split(","):
        key, equals, value = (part.strip() for part in item.partition("="))
        if not equals or key not in SHAPE_KEYS:
            raise argparse.ArgumentTypeError(
                f"{item!r}: expected key=value with key one of {', '.join(SHAPE_KEYS)}"
            )
        try:
            changes[key] = float(value)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{key}: must be a number, got {value!r}") from None
    return int(index), changes


def add_parser(commands: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    parser = commands.add_parser(
        "create",
        help="the creature creator: a window, or --out FILE for scripts",
        description="The creature creator: uniform settings, then per-tentacle changes, then"
        " export. Unset options keep the defaults (or the --from scene's values).",
    )
    parser.add_argument("--out", type=json_file, metavar="FILE", help="scene file to write")
    parser.add_argument(
        "--window", action="store_true", help="open the creator window even with --out"
    )
    parser.add_argument("--json", action="store_true", help="print the summary as JSON")
    parser.add_argument("--from", dest="source", metavar="SCENE", help="start from this scene")
    parser.add_argument("--creature", default="0", help="--from: creature name or index")
    parser.add_argument("--name", help="creature name (letters, digits, _)")
    for option, text in (
        ("--mantle-radius", "mantle radius (m)"),
        ("--mantle-height", "mantle height (m)"),
        ("--link-length", "first link's length (m)"),
        ("--link-radius", "first link's radius (m)"),
    ):
        parser.add_argument(option, type=positive_float, metavar="M", help=text)
    parser.add_argument("--tentacles", type=positive_int, metavar="N", help="tentacle count")
    parser.add_argument("--links", type=positive_int, metavar="N", help="links per tentacle")
    parser.add_argument(
        "--end-scale", type=positive_float, metavar="S", help="tip link size / first link size"
    )
    parser.add_argument(
        "--tentacle",
        type=tentacle_edit,
        action="append",
        default=[],
        metavar="K:KEY=VALUE,...",
        help="change tentacle K after the uniform build (keys: links, link_length,"
        " link_radius, end_scale); repeatable",
    )
    parser.set_defaults(handler=handle)


def handle(args: argparse.Namespace) -> int:
    try:
        design = make_design(args)
        if args.out is None or args.window:
            return open_window(design, args.out or Path(f"{design.name}.json"))
        design.export(args.out)
    except DesignError as error:
        option = OPTIONS.get(error.field, "--tentacle")
        print(f"error: argument {option}: {error.message}", file=sys.stderr)
        return 2
    count, links = len(design.tentacles), sum(t.links for t in design.tentacles)
    if args.json:
        report = {"scene": str(args.out), "creature": design.name}
        print(json.dumps({**report, "tentacles": count, "links": links}))
    else:
        print(f"{args.out}: creature {design.name!r}: {count} tentacles, {links} links")
    return 0


def open_window(design: CreatureDesign, out: Path) -> int:
    """The interactive creator on `design`; Export writes `out`."""
    require_display("create")
    from ecs_tentacles.render import configure

    configure(headless=False)
    from ecs_tentacles.creator.window import Creator

    creator = Creator(design, out)
    try:
        creator.run()
    finally:
        creator.close()
    return 0


def make_design(args: argparse.Namespace) -> CreatureDesign:
    """Apply the options in the creator's order: start, uniform build, tentacle edits."""
    if args.source:
        creature: int | str = int(args.creature) if args.creature.isdigit() else args.creature
        design = CreatureDesign.from_scene(args.source, creature)
    else:
        design = CreatureDesign()
    if args.name is not None:
        design.name = args.name
    uniform = {
        "mantle_radius": args.mantle_radius,
        "mantle_height": args.mantle_height,
        "count": args.tentacles,
        "links": args.links,
        "link_length": args.link_length,
        "link_radius": args.link_radius,
        "end_scale": args.end_scale,
    }
    if args.source is None or any(v is not None for k, v in uniform.items() if "mantle" not in k):
        design.build(**uniform)
    else:
        design.set_mantle(radius=args.mantle_radius, height=args.mantle_height)
    for index, changes in args.tentacle:
        if "links" in changes:
            changes["links"] = _whole(changes["links"])
        design.set_tentacle(index, **changes)
    return design


def _whole(value: float) -> int | float:
    return int(value) if value == int(value) else value
