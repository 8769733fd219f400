"""Benchmark: the sandbox as an artist directs a crowd: physics and drawn-frame times.

    python tools/bench_sandbox.py                      # 64 and 256 creatures on rocky ground
    python tools/bench_sandbox.py --crowd 64 --frames 120 --json
    python tools/bench_sandbox.py --crowd 64 --terrain flat --lod off
    python tools/bench_sandbox.py --still              # the camera framed once, then still

A crowd as `ecs-tentacles crowd N --terrain rocky` writes it, opened in the headless
sandbox at 1280 x 720 with the HUD shown and the camera framing every creature (`play
--camera frame-all`); the level of detail follows the camera as it does in the window.
Each frame is timed in two parts: `physics` (the sandbox's step: the level of detail's
choices and every system of one world frame) and `drawn` (the world and the HUD drawn,
ending with glFinish, so llvmpipe's rasterising counts). `--still` frames the crowd
once and leaves the camera where it is, as the window does until the player moves it
(without it the camera eases after the crowd every frame, as a `--video` does). Real
time is the frame's duration over the median physics time: >= 1.0 keeps up with the
clock. Medians over the measured frames, after a warm-up; the tiers are those at the end.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from typing import Any

from ecs_tentacles.cli.crowd import crowd_from_args
from ecs_tentacles.options import WorldOptions
from ecs_tentacles.render import configure


def crowd(count: int, terrain: str, seed: int) -> dict[str, Any]:
    """The scene `ecs-tentacles crowd COUNT --terrain TERRAIN --seed SEED` writes."""
    args = argparse.Namespace(
        seed=seed, spacing=None, idle=0.0, species=8, uniform=False, terrain=terrain
    )
    return crowd_from_args(count, args)


def bench(
    scene: dict[str, Any],
    frames: int,
    warmup: int,
    lod: bool | None,
    hud: bool,
    still: bool = False,
) -> dict[str, Any]:
    """Median ms of the physics and of a drawn frame, and the tiers at the end."""
    from pyglet import gl

    from ecs_tentacles.cli.play import camera_option
    from ecs_tentacles.render.sandbox import Sandbox

    sandbox = Sandbox(scene, WorldOptions(lod=lod), width=1280, height=720, headless=True, hud=hud)
    try:
        sandbox.aim(camera_option("frame-all"))
        physics, drawn = [], []
        for frame in range(warmup + frames):
            start = time.perf_counter()
            sandbox.step(1)
            stepped = time.perf_counter()
            if not still:
                sandbox.keep_framed(0.1)
            sandbox.render()
            gl.glFinish()
            if frame >= warmup:
                physics.append(stepped - start)
                drawn.append(time.perf_counter() - stepped)
        dt = sandbox.world.settings.dt
        physics_ms = 1000 * statistics.median(physics)
        return {
            "creatures": len(sandbox.world.physics),
            "frames": frames,
            "physics_ms": round(physics_ms, 2),
            "drawn_ms": round(1000 * statistics.median(drawn), 2),
            "realtime_factor": round(1000 * dt / physics_ms, 3),
            "tiers": sandbox.world.lod.counts(),
        }
    finally:
        sandbox.close()


def main() -> None:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--crowd", type=int, nargs="*", default=[64, 256], metavar="N")
    parser.add_argument("--terrain", choices=("flat", "rocky"), default="rocky")
    parser.add_argument("--frames", type=int, default=90)
    parser.add_argument("--warmup", type=int, default=30)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--lod", choices=("on", "off"), default=None)
    parser.add_argument("--no-hud", action="store_true")
    parser.add_argument("--still", action="store_true", help="frame once, then keep still")
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    if args.frames < 1 or args.warmup < 0 or any(n < 1 for n in args.crowd):
        parser.error("--frames and --crowd must be >= 1, --warmup >= 0")
    configure(headless=True)
    lod = None if args.lod is None else args.lod == "on"
    rows = []
    for count in args.crowd:
        scene = crowd(count, args.terrain, args.seed)
        row = {
            "crowd": count,
            "terrain": args.terrain,
            "camera": "still" if args.still else "eased",
        }
        row.update(bench(scene, args.frames, args.warmup, lod, not args.no_hud, args.still))
        rows.append(row)
        if not args.json:
            tiers = " / ".join(f"{n} {name}" for name, n in row["tiers"].items())
            print(
                f"crowd {count} on {args.terrain} ground: physics {row['physics_ms']:.1f} ms"
                f" ({row['realtime_factor']:.2f}x real time), drawn frame"
                f" {row['drawn_ms']:.1f} ms at 1280x720; tiers {tiers}",
                flush=True,
            )
    if args.json:
        json.dump(rows, sys.stdout, indent=2)
        print()


if __name__ == "__main__":
    main()
