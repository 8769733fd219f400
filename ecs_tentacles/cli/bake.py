"""`ecs-tentacles bake SCENE --seconds S --out FILE`: simulate headless, write every frame.

FILE's suffix picks the format: `.npz` a take (the compact, reproducible record),
`.usd`/`.usda`/`.usdc` a USD stage (needs the `usd` extra), `.glb` binary glTF. The
output is written to a temporary file beside FILE and renamed at the end, so an
interrupted bake never leaves a partial FILE (an existing FILE stays as it was).
`--validate` checks a USD FILE once written (`ecs_tentacles.cli.usd_validate`).
`--lod on|off` and `--focus X,Y,R` are written into the plan's scene (`physics.lod`), so
the take's scene hash says what the bake ran with and Ray shards and wedge variants
get them too. `--ray [ADDRESS]` bakes in shards on Ray and `--wedge PATH=VALUES` bakes variants
(`ecs_tentacles.cli.bake_ray`, `ecs_tentacles.distributed`).
"""

from __future__ import annotations

import argparse
import hashlib
import importlib.util
import json
import math
import sys
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from ecs_tentacles.cli import bake_ray
from ecs_tentacles.cli.arguments import counted, output_path
from ecs_tentacles.cli.skin_options import add_arguments as add_skin_arguments
from ecs_tentacles.cli.skin_options import skin_options
from ecs_tentacles.cli.usd_validate import add_argument as add_validate_argument
from ecs_tentacles.cli.usd_validate import validate_problem, validated
from ecs_tentacles.cli.world_options import CODE, PHYSICS, SEED, parents, world_options
from ecs_tentacles.distributed.driver import ShardFailed
from ecs_tentacles.distributed.wedge import WedgeError
from ecs_tentacles.export import SUFFIXES, work_units, write
from ecs_tentacles.export.bake import BakePlan, bake, bake_to_file
from ecs_tentacles.export.kinds import output_kind
from ecs_tentacles.export.skinned import Skin
from ecs_tentacles.output.progress import bar
from ecs_tentacles.skin.keys import KeyReport
from ecs_tentacles.skin.mesh import MeshError
from ecs_tentacles.take import Take, TakeError
from ecs_tentacles.take.tracks import tracks_of


def positive_float(text: str) -> float:
    """A finite number > 0 (argparse type)."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a number, got {text!r}") from None
    if not (value > 0 and math.isfinite(value)):
        raise argparse.ArgumentTypeError(f"must be a finite number > 0, got {text}")
    return value


def fps_float(text: str) -> float:
    """A frame rate in (0, 1000] (argparse type)."""
    value = positive_float(text)
    if value > 1000:
        raise argparse.ArgumentTypeError(f"must be <= 1000, got {text}")
    return value


output_file = output_path(*SUFFIXES)  # an output path with a known suffix


def usd_missing(path: Path) -> str | None:
    """The one-line problem when `path` is USD and usd-core is not installed, else None."""
    if output_kind(path) == "usd" and importlib.util.find_spec("pxr") is None:
        return "argument --out: writing USD needs usd-core: pip install 'ecs-tentacles[usd]'"
    return None


def add_parser(commands: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    parser = commands.add_parser(
        "bake",
        help="simulate a scene headless and write every frame to a take (.npz), USD or glTF",
        description="Simulate a scene headless and record every frame: mantle and link poses,"
        " sucker states, goals (and fur guides). The output is written atomically.",
        parents=parents(SEED, CODE, PHYSICS),
    )
    parser.add_argument("scene", metavar="SCENE", help="scene file or bundled scene name")
    parser.add_argument(
        "--seconds", type=positive_float, required=True, help="simulated seconds to bake"
    )
    parser.add_argument(
        "--out",
        type=output_file,
        required=True,
        metavar="FILE",
        help=f"output file; its suffix picks the format ({', '.join(SUFFIXES)})",
    )
    parser.add_argument(
        "--fps",
        type=fps_float,
        default=None,
        help="frames per second of the take (default: the scene's physics fps)",
    )
    parser.add_argument("--quiet", action="store_true", help="no progress bar")
    parser.add_argument("--json", action="store_true", help="print the summary as JSON")
    add_skin_arguments(parser)
    add_validate_argument(parser)
    bake_ray.add_arguments(parser)
    parser.add_argument(
        "--strict",
        action="store_true",
        help="write nothing and exit 1 if any creature's physics had to be recovered",
    )
    parser.set_defaults(handler=handle)


def handle(args: argparse.Namespace) -> int:
    problem = usd_missing(args.out)
    problem = problem or bake_ray.ray_problem(args) or validate_problem(args)
    if problem:
        print(f"error: {problem}", file=sys.stderr)
        return 2
    plan = BakePlan.make(args.scene, world_options(args), seconds=args.seconds, fps=args.fps)
    note = None
    try:  # a glb too large (or a mesh past 16-bit indices) is refused before anything is built
        skin = skin_options(args)
        problem = None if args.wedge else plan.glb_problem(args.out, skin, args.locators)
        note = None if args.wedge or problem else plan.glb_note(args.out, skin, args.locators)
    except (ValueError, MeshError) as error:  # bad skin options, a creature no mesh fits
        problem = str(error)
    if problem:
        print(f"error: {problem}", file=sys.stderr)
        return 2
    if note:
        print(f"note: {note}", file=sys.stderr)
    problem = plan.size_problem()
    if problem:
        print(f"error: argument --seconds: {problem}", file=sys.stderr)
        return 2
    if plan.intervals < 1:
        print(
            f"error: argument --seconds: {args.seconds:g} s is less than one frame at"
            f" {plan.fps:g} fps",
            file=sys.stderr,
        )
        return 2
    if args.wedge:
        try:
            return bake_ray.run_wedge(args, plan, save)
        except WedgeError as error:
            print(f"error: {error}", file=sys.stderr)
            return 2
    print(
        f"bake: {plan.source} -> {args.out}: {plan.frames} frames at {plan.fps:g} fps"
        f" (simulated at {plan.sim_fps:g} fps), seed {plan.seed}",
        file=sys.stderr,
        flush=True,
    )
    try:
        skin = skin_options(args)
    except ValueError as error:
        print(f"error: {error}", file=sys.stderr)
        return 2
    if args.ray is None and output_kind(args.out) == "take":
        return _bake_streamed(args, plan)
    if args.ray is not None:
        try:
            take = bake_ray.bake_on_ray(args, plan)
        except ShardFailed as error:
            print(f"error: {error}", file=sys.stderr)
            return 1
    else:
        take = bake(plan, world_options(args), progress=not args.quiet)
    if _recoveries_refused(take.header, args.strict):
        return 1
    try:
        skinned = save(take, args.out, progress=not args.quiet, skin=skin, locators=args.locators)
    except MeshError as error:  # e.g. tentacle bases that overlap on the mantle
        print(f"error: {error}", file=sys.stderr)
        return 2
    except TakeError as error:  # the run made numbers no take may hold (a plugin's NaN)
        print(f"error: {error}", file=sys.stderr)
        return 1
    getattr(args, "after_write", lambda: None)()
    print(summary(take, args.out, args.json, skinned))
    return validated(args.out, progress=not args.quiet) if args.validate else 0


def _recoveries_refused(header: Mapping[str, object], strict: bool) -> bool:
    """Tell of physics recoveries in the take (an error with --strict: True)."""
    health = header["health"]
    if not isinstance(health, dict) or not health["recoveries"]:  # (a dict: as recorded)
        return False
    frames = sorted({e["frame"] for e in health["events"]})
    shown = ", ".join(map(str, frames[:8])) + (", ..." if len(frames) > 8 else "")
    print(
        f"{'error' if strict else 'warning'}: physics recovered {health['recoveries']}"
        f" times, {health['frozen']} creatures frozen (take frames {shown};"
        " marked in the take header)",
        file=sys.stderr,
    )
    return strict


def _bake_streamed(args: argparse.Namespace, plan: BakePlan) -> int:
    """A bake to a take file, written as the frames come (memory does not grow with the
    shot); with --strict a take with physics recoveries is not kept."""

    def accept(header: dict[str, object]) -> bool:
        return not _recoveries_refused(header, args.strict)

    try:
        header = bake_to_file(
            plan, args.out, world_options(args), progress=not args.quiet, accept=accept
        )
    except TakeError as error:  # the run made numbers no take may hold (a plugin's NaN)
        print(f"error: {error}", file=sys.stderr)
        return 1
    if header is None:
        return 1
    getattr(args, "after_write", lambda: None)()
    print(summary(header, args.out, args.json))
    return 0


def save(
    take: Take,
    path: Path,
    *,
    progress: bool,
    skin: Skin | None = None,
    locators: bool | None = None,
) -> KeyReport | None:
    """Write `take` to `path` in the format its suffix names, with a bar on stderr (the
    take's bytes, the creatures of a skinned file, the bodies of a rigid one); returns the
    key report when skinned. `locators`: as `export.write`."""
    total, unit = work_units(take, path, skin)
    with bar(total, f"write {path.name}", unit, progress=progress) as shown:
        return write(take, path, shown.update, skin, locators)


def report(take: Take | dict[str, Any], path: Path) -> dict[str, Any]:
    """What was written and the file's SHA-256 (equal for equal bakes); counts of
    creatures, bodies, suckers and of every points track's items (goals). `take`: the
    take, or the header of one written as it was baked."""
    header = take if isinstance(take, dict) else take.header
    return {
        "out": str(path),
        "frames": header["frames"],
        "fps": float(header["fps"]),
        **{key: len(header[key]) for key in ("creatures", "bodies", "suckers", *_points(header))},
        "sha256": _sha256(path),
        "recoveries": header.get("health", {}).get("recoveries", 0),
    }


def _sha256(path: Path) -> str:
    """SHA-256 of a file, read a MiB at a time (a film crowd's take is gigabytes)."""
    digest = hashlib.sha256()
    with path.open("rb") as handle:
        for block in iter(lambda: handle.read(1024**2), b""):
            digest.update(block)
    return digest.hexdigest()


def _points(header: dict[str, object]) -> list[str]:
    """The header keys of the take's points tracks (`goals`, ...)."""
    return [track.key for track in tracks_of(header) if track.kind == "points"]


def summary(
    take: Take | dict[str, object],
    path: Path,
    as_json: bool = False,
    skinned: KeyReport | None = None,
) -> str:
    """The report as a sentence (a second line for skinned creatures), or as JSON."""
    header = take if isinstance(take, dict) else take.header
    r = report(header, path)
    if skinned is not None:
        r["skinned"] = skinned.line()
    if as_json:
        return json.dumps(r)
    items = "".join(f", {counted(r[key], key.removesuffix('s'))}" for key in _points(header))
    line = (
        f"{path}: {r['frames']} frames at {r['fps']:g} fps, {counted(r['creatures'], 'creature')},"
        f" {r['bodies']} bodies, {counted(r['suckers'], 'sucker')}{items}; sha256 {r['sha256']}"
    )
    if skinned is None:
        return line
    return f"{line}\n{path}: skinned, {path.stat().st_size} bytes, {r['skinned']}"
