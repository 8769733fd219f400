"""Benchmark: what long goal paths cost: building the world, the goals track's first
recorded frame (every goal appears) and a recorded frame in which no goal changed.

    python tools/bench_goals.py                          # 64 creatures x 256, 512, 1,024 goals
    python tools/bench_goals.py --creatures 8 --goals 128,256 --json

One row per path length, with each cost's ratio to the previous row's: building and the
first frame grow with the goals (twice the goals, about twice the time: linear), a frame
with no change stays about the same. On cb9ca9a both grew with the square (each append
renumbered the whole path, each new locator counted the locators before it): a bake of
64 creatures x 1,024 goals, 1 s at 60 fps, took 115 s, 11.9 s once linear (`run`: 6.6 s).
"""

from __future__ import annotations

import argparse
import json
import statistics
import time
from typing import Any

import numpy as np

from ecs_tentacles.creator.crowd import crowd_scene
from ecs_tentacles.export.recording import TakeRecorder
from ecs_tentacles.world import World


def goal_scene(creatures: int, goals: int) -> dict[str, Any]:
    """A crowd of `creatures`, each with a path of `goals` goals scattered within 1 m."""
    scene = crowd_scene(creatures, 0)
    rng = np.random.default_rng(0)
    for creature in scene["creatures"]:
        x, y = creature["position"][:2]
        offsets = rng.uniform(-1.0, 1.0, (goals, 2))
        creature["goals"] = [
            {"position": [round(x + dx, 4), round(y + dy, 4)]} for dx, dy in offsets.tolist()
        ]
    return scene


def bench(creatures: int, goals: int, repeats: int = 5) -> dict[str, Any]:
    """Seconds to build the world; median milliseconds of a recorder's first frame and of
    its next one (no goal changed), over `repeats` recorders of the same world."""
    scene = goal_scene(creatures, goals)
    start = time.perf_counter()
    world = World.from_scene(scene)
    built = time.perf_counter() - start
    first, same = [], []
    try:
        for _ in range(repeats):
            recorder = TakeRecorder(world)
            start = time.perf_counter()
            recorder.capture()
            first.append(time.perf_counter() - start)
            start = time.perf_counter()
            recorder.capture()
            same.append(time.perf_counter() - start)
    finally:
        world.close()
    return {
        "creatures": creatures,
        "goals": goals,
        "build_s": round(built, 3),
        "first_frame_ms": round(1000 * statistics.median(first), 2),
        "unchanged_frame_ms": round(1000 * statistics.median(same), 3),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--creatures", type=int, default=64)
    parser.add_argument("--goals", default="256,512,1024", help="path lengths, comma-separated")
    parser.add_argument("--repeats", type=int, default=5, help="recorders timed per row")
    parser.add_argument("--json", action="store_true", help="one JSON object per row")
    args = parser.parse_args()
    bench(1, 1, 1)  # imports and first-use caches out of the first row
    previous: dict[str, Any] | None = None
    for goals in (int(text) for text in args.goals.split(",")):
        row = bench(args.creatures, goals, args.repeats)
        if previous is not None:
            for key in ("build_s", "first_frame_ms", "unchanged_frame_ms"):
                row[f"{key}_ratio"] = round(row[key] / max(previous[key], 1e-9), 2)
        previous = row
        if args.json:
            print(json.dumps(row))
        else:
            ratios = "  ".join(f"{k}={v}" for k, v in row.items() if k.endswith("_ratio"))
            print(
                f"{row['creatures']} x {goals} goals: build {row['build_s']:.2f} s, first frame"
                f" {row['first_frame_ms']:.1f} ms, unchanged frame"
                f" {row['unchanged_frame_ms']:.2f} ms  {ratios}"
            )


if __name__ == "__main__":
    main()
