"""What MuJoCo's step costs the systems around it: each system's in-frame time with the
physics stepping as usual, and with the stepping left out (the world's state stays put).

    python tools/step_cache_cost.py                     # 16 creatures, 2 threads
    python tools/step_cache_cost.py --crowd 64 --threads 1 --frames 60 --json

A uniform crowd, level of detail off, is run `--warmup` frames and saved; then, from that
same saved state, `--frames` frames with stepping and as many without, alternately
(`--repeat` times each), every system timed. The systems do the same work either way
(the poses they read change only a little in a frame); what differs is what MuJoCo's
step has left in the caches: after a step, every system first touches data and code
the step has pushed out. Medians per system and of the systems' sum (the physics
system itself reported apart, with its stepping). Progress goes to stderr.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from collections import defaultdict
from collections.abc import Callable
from typing import Any

import numpy as np

from ecs_tentacles.creator.crowd import crowd_scene
from ecs_tentacles.world import World

MODES = ("stepped", "not stepped")


def _timed(process: Callable[..., Any], name: str, seconds: dict[str, float]) -> Callable[..., Any]:
    def run(world: Any, dt: float) -> Any:
        start = time.perf_counter()
        try:
            return process(world, dt)
        finally:
            seconds[name] += time.perf_counter() - start

    return run


def measure(creatures: int, threads: int, frames: int, warmup: int, repeat: int) -> dict[str, Any]:
    """Median microseconds a frame per system, with and without the physics stepping."""
    world = World.from_scene(crowd_scene(creatures, uniform=True), threads=threads, lod=False)
    try:
        print(f"warming up: {warmup} frames", file=sys.stderr)
        world.step(warmup)
        saved = world.snapshot()
        seconds: dict[str, float] = defaultdict(float)
        for system in world.schedule:
            system.process = _timed(system.process, system.name, seconds)  # type: ignore[method-assign]
        physics = world.physics
        stepping = physics.step
        times: dict[str, dict[str, list[float]]] = {mode: defaultdict(list) for mode in MODES}
        moved = dict.fromkeys(MODES, 0.0)  # the farthest a body went in a run (m)
        for index in range(repeat):
            for mode in MODES:
                print(f"run {index + 1}/{repeat}: {mode}", file=sys.stderr)
                world.restore(saved)
                start = world.transforms.pos.copy()
                physics.step = stepping if mode == MODES[0] else _not_stepped  # type: ignore[method-assign]
                for _ in range(frames):
                    seconds.clear()
                    world.step(1)
                    for name, took in seconds.items():
                        times[mode][name].append(took * 1e6)
                    others = sum(t for name, t in seconds.items() if name != "physics")
                    times[mode]["(systems but physics)"].append(others * 1e6)
                went = float(np.linalg.norm(world.transforms.pos - start, axis=1).max())
                moved[mode] = max(moved[mode], went)
        del physics.step
    finally:
        world.close()
    medians = {mode: {k: statistics.median(v) for k, v in t.items()} for mode, t in times.items()}
    return {"creatures": creatures, "threads": threads, "frames": frames, "repeat": repeat,
            "us_per_frame": medians, "moved_m": moved}  # fmt: skip


def _not_stepped(*args: Any, **kwargs: Any) -> None:
    """The physics backend's step, leaving every state as it is."""


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--crowd", type=int, default=16, help="creatures (default 16)")
    parser.add_argument("--threads", type=int, default=2, help="stepping threads (default 2)")
    parser.add_argument("--frames", type=int, default=40, help="timed frames a run")
    parser.add_argument("--warmup", type=int, default=90, help="frames run first, untimed")
    parser.add_argument("--repeat", type=int, default=2, help="runs of each kind (default 2)")
    parser.add_argument("--json", action="store_true", help="one JSON object")
    args = parser.parse_args(argv)
    for name in ("crowd", "threads", "frames", "repeat"):
        if getattr(args, name) < 1:
            parser.error(f"--{name} must be >= 1, got {getattr(args, name)}")
    if args.warmup < 0:
        parser.error(f"--warmup must be >= 0, got {args.warmup}")
    result = measure(args.crowd, args.threads, args.frames, args.warmup, args.repeat)
    if args.json:
        print(json.dumps(result))
        return 0
    stepped, still = (result["us_per_frame"][mode] for mode in MODES)
    print(f"{args.crowd} creatures, {args.threads} threads: median us a frame")
    print(f"{'system':24s} {'stepped':>9s} {'not stepped':>12s} {'ratio':>6s}")
    for name, value in stepped.items():
        other = still.get(name, 0.0)
        ratio = f"{value / other:6.2f}" if other > 0 else "     -"
        print(f"{name:24s} {value:9.1f} {other:12.1f} {ratio}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
