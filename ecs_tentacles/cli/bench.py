"""`ecs-tentacles bench [SCENE | --crowd N]`: headless build and frame timings.

    ecs-tentacles bench --crowd 64 --frames 120 --threads 2 --json
    ecs-tentacles bench octopus
    ecs-tentacles bench --crowd 1024 --uniform --lod off

What is measured, and how the bare MuJoCo figure is taken in the same run, is
described in `ecs_tentacles.cli.measure`.
"""

from __future__ import annotations

import argparse
import json
import os

from ecs_tentacles.cli.arguments import bounded_int, counted
from ecs_tentacles.cli.crowd import add_crowd_options, crowd_from_args, crowd_size
from ecs_tentacles.cli.measure import BLOCK, WARMUP, bench
from ecs_tentacles.cli.run import tier_line
from ecs_tentacles.cli.world_options import CODE, PHYSICS, parents, world_options
from ecs_tentacles.scene.load import resolve_scene_path


def add_parser(commands: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    parser = commands.add_parser(
        "bench",
        help="time building and running a scene or a generated crowd, headless",
        description=(
            "Build a scene (or a generated crowd), run it headless and report build seconds,"
            " ms per frame, per system, and MuJoCo stepping the same models bare."
        ),
        parents=parents(CODE, PHYSICS),
    )
    source = parser.add_mutually_exclusive_group(required=True)
    source.add_argument("scene", nargs="?", metavar="SCENE", help="scene file or bundled name")
    source.add_argument(
        "--crowd",
        type=crowd_size,
        metavar="N",
        help="bench a crowd of N creatures (as `ecs-tentacles crowd N` writes)",
    )
    parser.add_argument(
        "--frames", type=bounded_int(1, 1_000_000), default=120, help="timed frames (default 120)"
    )
    parser.add_argument(
        "--block",
        type=bounded_int(1, 10_000),
        default=BLOCK,
        help=f"frames per interleaved framework / bare block (default {BLOCK})",
    )
    parser.add_argument(
        "--warmup",
        type=bounded_int(0, 1_000_000),
        default=WARMUP,
        help=f"untimed frames before timing (default {WARMUP})",
    )
    parser.add_argument("--json", action="store_true", help="print the result as one JSON object")
    parser.add_argument("--quiet", action="store_true", help="no progress bars")
    parser.add_argument(
        "--no-sleep", action="store_true", help="step idle creatures too (to see what sleep saves)"
    )
    add_crowd_options(parser)
    parser.set_defaults(handler=handle)


def handle(args: argparse.Namespace) -> int:
    if args.crowd is not None:
        source: str | os.PathLike[str] | dict[str, object] = crowd_from_args(args.crowd, args)
        label = f"crowd of {args.crowd} (seed {args.seed}, {args.idle:.0%} idle)"
    else:
        source = resolve_scene_path(args.scene)
        label = str(source)
    result = bench(
        source,
        world_options(args).but(seed=None),  # (--seed is the generated crowd's)
        frames=args.frames,
        block=args.block,
        warmup=args.warmup,
        sleep=not args.no_sleep,
        progress=not args.quiet,
    )
    if args.json:
        print(json.dumps(result))
        return 0
    print(
        f"{label}: {counted(result['creatures'], 'creature')}, {result['bodies']} bodies,"
        f" {counted(result['compiles'], 'shared model')} ({result['asleep']} asleep at the"
        f" end), {counted(result['threads'], 'thread')};"
        f" built in {result['build_s']:.2f} s"
    )
    print(
        f"  {result['frames']} frames: {result['frame_ms']:.2f} ms/frame"
        f" ({result['realtime_factor']:.2f}x real time), physics {result['physics_ms']:.2f} ms,"
        f" bare MuJoCo {result['raw_mujoco_ms']:.2f} ms, overhead"
        f" {result['overhead_ratio']:.3f}x; {result['rss_mb']:.0f} MB resident"
    )
    changes = f"on: {result['promotions']} promotions, {result['demotions']} demotions"
    lod = changes if result["lod"] else "off"
    print(f"  tiers at the end: {tier_line(result['tiers'])} (level of detail {lod})")
    systems = sorted(result["systems"].items(), key=lambda item: -item[1])
    print("  systems (ms/frame): " + ", ".join(f"{name} {ms:.3f}" for name, ms in systems))
    return 0
