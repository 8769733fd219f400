"""Benchmark: where a headless frame's time goes, and the framework's overhead.

    python tools/bench_frame.py                       # the bundled scenes
    python tools/bench_frame.py octopus --frames 300 --repeats 7 --json

Each system's `process` and MuJoCo's `mj_step` are timed inside real frames of a
running scene (locomotion on). The framework's overhead is everything that is not
`mj_step`, as a share of `mj_step` (target: <= 10 %). Medians over repeats.
"""

from __future__ import annotations

import argparse
import json
import statistics
import time
from collections import defaultdict
from typing import Any

from ecs_tentacles.cli.measure import time_systems, timed
from ecs_tentacles.scene.load import bundled_scene_names
from ecs_tentacles.world import World


def bench_scene(scene: str, frames: int, repeats: int) -> dict[str, Any]:
    """Median ms per frame: total, mj_step, each system without its MuJoCo time."""
    world = World.from_scene(scene)
    world.step(frames)  # warm up: goals chosen, suckers in use
    buckets = time_systems(world)
    mujoco_time = [0.0]
    world.physics.step = timed(world.physics.step, mujoco_time)  # type: ignore[method-assign]
    per_frame: dict[str, list[float]] = defaultdict(list)
    for _ in range(repeats):
        for bucket in [*buckets.values(), mujoco_time]:
            bucket[0] = 0.0
        start = time.perf_counter()
        world.step(frames)
        total = time.perf_counter() - start
        per_frame["total"].append(total * 1000 / frames)
        per_frame["mj_step"].append(mujoco_time[0] * 1000 / frames)
        for name, bucket in buckets.items():
            own = bucket[0] - (mujoco_time[0] if name == "physics" else 0.0)
            per_frame[name].append(own * 1000 / frames)
    world.close()
    medians = {name: statistics.median(values) for name, values in per_frame.items()}
    framework = medians["total"] - medians["mj_step"]
    return {
        "scene": scene,
        "frames": frames,
        "repeats": repeats,
        "ms_per_frame": {k: round(v, 4) for k, v in medians.items()},
        "overhead_percent": round(100 * framework / medians["mj_step"], 2),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("scenes", nargs="*", help="scene files or bundled names (default: all)")
    parser.add_argument("--frames", type=int, default=120)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    rows = [bench_scene(s, args.frames, args.repeats) for s in args.scenes or bundled_scene_names()]
    if args.json:
        print(json.dumps(rows, indent=2))
        return
    for row in rows:
        ms = row["ms_per_frame"]
        print(
            f"{row['scene']}: {ms['total']:.3f} ms/frame, mj_step {ms['mj_step']:.3f} ms,"
            f" framework {row['overhead_percent']:.1f} %"
        )
        systems = sorted((k for k in ms if k not in ("total", "mj_step")), key=lambda k: -ms[k])
        print("    " + ", ".join(f"{k} {1000 * ms[k]:.0f} us" for k in systems))


if __name__ == "__main__":
    main()
