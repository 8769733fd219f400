"""`ecs-tentacles export TAKE --out FILE`: convert a take (.npz) to USD or glTF.

The suffix of FILE picks the format (`.usd`, `.usda`, `.usdc`, `.glb`); the file is
written atomically. Creatures are skinned (a mesh on a joint skeleton with rotation
keys) unless `--rigid`; each creature gets a material of its sandbox colour. Suckers and
goals are locators with `--locators` (the default for `--rigid`; `--no-locators` leaves
them out). A file that is not a take gives one line naming it and exit 2. `--validate`
checks the written USD (`ecs_tentacles.cli.usd_validate`): exit 1 on an error.
"""

from __future__ import annotations

import argparse
import sys

from ecs_tentacles.cli.arguments import output_path
from ecs_tentacles.cli.bake import save, summary, usd_missing
from ecs_tentacles.cli.skin_options import add_arguments as add_skin_arguments
from ecs_tentacles.cli.skin_options import skin_options
from ecs_tentacles.cli.usd_validate import add_argument as add_validate_argument
from ecs_tentacles.cli.usd_validate import validate_problem, validated
from ecs_tentacles.export import write_usd_stream
from ecs_tentacles.export.glb_size import glb_note, glb_problem, glb_size, shapes_of_header
from ecs_tentacles.export.kinds import output_kind
from ecs_tentacles.export.skinned import Skin
from ecs_tentacles.output.progress import bar, status
from ecs_tentacles.skin.mesh import MeshError
from ecs_tentacles.take import Take

FORMATS = (".usd", ".usda", ".usdc", ".glb")


converted_file = output_path(*FORMATS)  # an output path for a conversion: USD or glTF


def add_parser(commands: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    parser = commands.add_parser(
        "export",
        help="convert a take (.npz from `bake`) to USD or glTF",
        description="Convert a take to USD (.usd, .usda, .usdc) or binary glTF (.glb).",
    )
    parser.add_argument("take", metavar="TAKE", help="a take file written by `bake --out X.npz`")
    parser.add_argument(
        "--out",
        type=converted_file,
        required=True,
        metavar="FILE",
        help=f"output file; its suffix picks the format ({', '.join(FORMATS)})",
    )
    parser.add_argument("--quiet", action="store_true", help="no progress bar")
    parser.add_argument("--json", action="store_true", help="print the summary as JSON")
    add_skin_arguments(parser)
    add_validate_argument(parser)
    parser.set_defaults(handler=handle)


def glb_refusal(args: argparse.Namespace, skin: Skin | None) -> str | None:
    """Why the glb --out names cannot hold the take (one line), or None (and None for
    USD): counted from the take's header before a frame is read (`export.glb_size`).
    A glb past what Blender imports gets a note on stderr."""
    if output_kind(args.out) != "gltf":
        return None
    size = glb_size(
        shapes_of_header(Take.read_header(args.take)),  # TakeError: one line, exit 2
        None if skin is None else skin.detail,
        None if skin is None else skin.keys,
        args.locators,
    )
    problem = glb_problem(args.out, size, (".usdc",), "export")
    note = None if problem else glb_note(args.out, size)
    if note:
        print(f"note: {note}", file=sys.stderr)
    return problem


def handle(args: argparse.Namespace) -> int:
    problem = usd_missing(args.out) or validate_problem(args)
    if problem:
        print(f"error: {problem}", file=sys.stderr)
        return 2
    try:
        skin = skin_options(args)
    except ValueError as error:
        print(f"error: {error}", file=sys.stderr)
        return 2
    try:
        problem = glb_refusal(args, skin)
    except MeshError as error:  # e.g. tentacle bases that overlap on the mantle
        problem = str(error)
    if problem:
        print(f"error: {problem}", file=sys.stderr)
        return 2
    if output_kind(args.out) == "usd":
        return _export_usd(args, skin)
    with status(f"export: reading {args.take}", progress=not args.quiet):
        take = Take.load(args.take)  # TakeError: one line, exit 2
    try:
        skinned = save(take, args.out, progress=not args.quiet, skin=skin, locators=args.locators)
    except MeshError as error:  # e.g. tentacle bases that overlap on the mantle
        print(f"error: {error}", file=sys.stderr)
        return 2
    print(summary(take, args.out, args.json, skinned))
    return validated(args.out, progress=not args.quiet) if args.validate else 0


def _export_usd(args: argparse.Namespace, skin: Skin | None) -> int:
    """USD written as the take is read, a chunk of frames at a time (memory does not
    grow with the shot); a bar in frames."""
    from ecs_tentacles.take.stream import open_take

    with status(f"export: opening {args.take}", progress=not args.quiet):
        source = open_take(args.take)  # TakeError: one line, exit 2
    with (
        source,
        bar(source.frames, f"write {args.out.name}", "frame", progress=not args.quiet) as shown,
    ):
        try:
            skinned = write_usd_stream(source, args.out, shown.update, skin, args.locators)
        except MeshError as error:  # e.g. tentacle bases that overlap on the mantle
            print(f"error: {error}", file=sys.stderr)
            return 2
    print(summary(source.header, args.out, args.json, skinned))
    return validated(args.out, progress=not args.quiet) if args.validate else 0
