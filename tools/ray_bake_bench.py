"""Ray bake benchmark: one crowd baked locally on 1 and 2 threads and on Ray, same run.

    python tools/ray_bake_bench.py                       # 256 creatures, 2 s, 8 stripes
    python tools/ray_bake_bench.py --creatures 64 --seconds 1 --stripes 4 --json

The crowd is `crowd_scene(N, uniform=True)`. Its creatures start 0.4 m apart and
cross the middle, so the shard planner rightly finds one set (any may meet another);
the bench therefore declares shards in the scene: `--stripes` vertical stripes of the
grid. The bake's contact check proves them apart (or joins and re-bakes the stripes
that met, and the table says how many). Ray runs a local cluster of `--workers` CPUs.

Reports wall seconds and speed-up against 1 thread, Ray's start-up, its overhead
per task ((wall x workers - seconds inside the tasks) / tasks), the bytes that came
back from the workers, and whether the Ray take equals the local one byte for byte.
CPU seconds (this process for local bakes, the workers inside their tasks for Ray)
and the load average show how much of a wall time was other programs' doing.
Not a test: run it by hand on a quiet machine (numbers move with the load).
"""

from __future__ import annotations

import argparse
import hashlib
import io
import json
import os
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

from ecs_tentacles.creator.crowd import crowd_scene
from ecs_tentacles.distributed.driver import ray_bake, start_ray
from ecs_tentacles.export.bake import BakePlan, bake
from ecs_tentacles.options import WorldOptions
from ecs_tentacles.take import Take, write_npz


def striped(creatures: int, stripes: int) -> dict[str, Any]:
    """The uniform crowd with `shards`: creatures cut into `stripes` by x position."""
    scene = crowd_scene(creatures, uniform=True)
    order = sorted(scene["creatures"], key=lambda c: (c["position"][0], c["name"]))
    size = -(-len(order) // stripes)
    scene["shards"] = [[c["name"] for c in order[i : i + size]] for i in range(0, len(order), size)]
    return scene


def sha(take: Take) -> str:
    buffer = io.BytesIO()
    write_npz(buffer, take.arrays())
    return hashlib.sha256(buffer.getvalue()).hexdigest()


def run(creatures: int, seconds: float, stripes: int, workers: int) -> dict[str, Any]:
    import ray

    plan = BakePlan.make(striped(creatures, stripes), seconds=seconds, fps=30)
    rows: dict[str, Any] = {"creatures": creatures, "seconds": seconds, "frames": plan.frames}
    rows["load_before"] = os.getloadavg()[0]
    takes = {}
    for threads in (1, 2):
        print(f"local, {threads} thread(s)...", file=sys.stderr, flush=True)
        start, cpu = time.perf_counter(), time.process_time()
        takes[threads] = bake(plan, WorldOptions(threads=threads), progress=False)
        rows[f"local_{threads}_s"] = time.perf_counter() - start
        rows[f"local_{threads}_cpu_s"] = time.process_time() - cpu
    print(f"ray, {workers} workers...", file=sys.stderr, flush=True)
    start = time.perf_counter()
    start_ray(None, workers)
    rows["ray_start_s"] = time.perf_counter() - start
    try:
        with tempfile.TemporaryDirectory() as folder:
            start = time.perf_counter()
            take, stats = ray_bake(plan, Path(folder) / "work", progress=False, note=lambda _: None)
            rows["ray_s"] = time.perf_counter() - start
    finally:
        ray.shutdown()
    tasks = stats.baked
    rows.update(
        shards=len(stats.plan.shards) if stats.plan else 0,
        tasks=tasks,
        rebaked=stats.rebaked,
        inside_tasks_s=sum(stats.task_seconds),
        tasks_cpu_s=sum(stats.task_cpu_seconds),
        load_after=os.getloadavg()[0],
        overhead_per_task_s=(rows["ray_s"] * workers - sum(stats.task_seconds)) / max(1, tasks),
        bytes_back=stats.result_bytes,
        identical=sha(take) == sha(takes[1]) == sha(takes[2]),
    )
    return rows


def table(r: dict[str, Any], workers: int) -> str:
    base = r["local_1_s"]
    lines = [
        f"{r['creatures']} creatures, {r['seconds']:g} s ({r['frames']} frames at 30 fps)",
        "| run | wall s | speed-up | CPU s |",
        "| --- | ---: | ---: | ---: |",
        f"| local, 1 thread | {base:.1f} | 1.00 | {r['local_1_cpu_s']:.1f} |",
        f"| local, 2 threads | {r['local_2_s']:.1f} | {base / r['local_2_s']:.2f} |"
        f" {r['local_2_cpu_s']:.1f} |",
        f"| Ray, {workers} workers ({r['shards']} shards) | {r['ray_s']:.1f} |"
        f" {base / r['ray_s']:.2f} | {r['tasks_cpu_s']:.1f} (in tasks) |",
        "",
        f"load average {r['load_before']:.1f} before, {r['load_after']:.1f} after"
        f" on {os.cpu_count()} CPUs (shared machine: wall times move with it)",
        f"Ray start-up {r['ray_start_s']:.1f} s (not in the Ray wall time); {r['tasks']} tasks"
        f" ({r['rebaked']} re-baked together), {r['inside_tasks_s']:.1f} s inside them;"
        f" overhead per task {r['overhead_per_task_s']:.2f} s; {r['bytes_back'] / 1e6:.1f} MB"
        f" came back; Ray take identical to the local ones: {r['identical']}",
    ]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--creatures", type=int, default=256)
    parser.add_argument("--seconds", type=float, default=2.0)
    parser.add_argument("--stripes", type=int, default=8)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--json", action="store_true", help="one JSON object instead of a table")
    args = parser.parse_args(argv)
    rows = run(args.creatures, args.seconds, args.stripes, args.workers)
    print(json.dumps(rows) if args.json else table(rows, args.workers))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
