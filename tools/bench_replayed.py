"""Benchmark: what a replayed (KINEMATIC) creature costs a frame, part by part.

    python tools/bench_replayed.py                         # 10,000 uniform octopuses, 2 threads
    python tools/bench_replayed.py --crowd 3000 --frames 60 --json

Builds `ecs-tentacles crowd N --uniform` (the crowd `bench --crowd N --uniform` runs),
steps `--warmup` frames (90: past the second after which nobody reading the fur lets
the replayed creatures' strands rest), then times `--frames` frames with every system's `process`
and the per-frame calls whose work grows with the number of replayed creatures wrapped
(wall seconds, summed). Prints each one's ms a frame and microseconds per KINEMATIC
creature (the mean count over the timed frames), and the frame's total per replayed
creature less the stepping (`PhysicsBackend.step`: MuJoCo and the bookkeeping of the
creatures it steps, the reduced ones at 10,000, which do not scale with the replayed
ones; the proxies' refresh between its rounds is in it too).
The parts overlap (a part inside a system is also in the system's figure). Each part
also gets the calling (main) thread's CPU time per replayed creature, and so does the
frame less the stepping (`cpu_us_per_replayed_less_stepping`): on a shared machine
that moves far less with the load than wall time. One run: state the machine's load
(`uptime`) with its figures.
"""

from __future__ import annotations

import argparse
import json
import statistics
import time
from collections.abc import Callable
from typing import Any

import numpy as np

from ecs_tentacles.cli.measure import time_systems
from ecs_tentacles.clips.replay import ClipReplay
from ecs_tentacles.creator.crowd import crowd_scene
from ecs_tentacles.physics.backend import PhysicsBackend
from ecs_tentacles.physics.health import HealthCheck
from ecs_tentacles.physics.lod import LevelOfDetail
from ecs_tentacles.physics.proxies import ContactProxies
from ecs_tentacles.physics.tiers import KINEMATIC
from ecs_tentacles.world import World

# (label, class, method): calls inside the frame whose work grows with the crowd
PARTS: list[tuple[str, type, str]] = [
    ("lod_update", LevelOfDetail, "update"),
    ("proxies_sense", ContactProxies, "sense"),
    ("proxies_pair_gaps", ContactProxies, "pair_gaps"),
    ("proxies_update", ContactProxies, "update"),
    ("proxies_refresh", ContactProxies, "refresh"),
    ("replay_advance", ClipReplay, "advance"),
    ("sync", PhysicsBackend, "sync"),
    ("health_check", HealthCheck, "check"),
    ("stepping", PhysicsBackend, "step"),
]


def _wrap(owner: type, name: str, bucket: list[float]) -> Callable[[], None]:
    """Time every call of `owner.name` into `bucket[0]` (wall) and `bucket[1]` (the
    calling thread's CPU time); returns the undo."""
    original = getattr(owner, name)

    def wrapper(*args: Any, **kwargs: Any) -> Any:
        start, cpu = time.perf_counter(), time.thread_time()
        try:
            return original(*args, **kwargs)
        finally:
            bucket[0] += time.perf_counter() - start
            bucket[1] += time.thread_time() - cpu

    setattr(owner, name, wrapper)
    return lambda: setattr(owner, name, original)


def run(
    crowd: int, frames: int, warmup: int, threads: int, seed: int, reduced: int | None = None
) -> dict[str, Any]:
    """Build the crowd, time it, and return the split (see the module doc); `reduced`:
    the scene's budget of REDUCED creatures (None: the default)."""
    scene = crowd_scene(crowd, seed=seed, uniform=True)
    if reduced is not None:
        scene.setdefault("physics", {}).setdefault("lod", {})["reduced"] = reduced
    start = time.perf_counter()
    world = World.from_scene(scene, threads=threads)
    build_s = time.perf_counter() - start
    try:
        world.step(warmup)
        systems = time_systems(world)
        parts = {label: [0.0, 0.0] for label, _, _ in PARTS}
        undo = [_wrap(owner, name, parts[label]) for label, owner, name in PARTS]
        kinematic, took, cpu = [], [], []
        try:
            for bucket in systems.values():
                bucket[0] = 0.0
            for _ in range(frames):
                kinematic.append(int(np.count_nonzero(world.physics.roster.tier == KINEMATIC)))
                began, began_cpu = time.perf_counter(), time.thread_time()
                world.step(1)
                took.append(time.perf_counter() - began)
                cpu.append(time.thread_time() - began_cpu)
        finally:
            for restore in undo:
                restore()
    finally:
        world.close()
    replayed = statistics.mean(kinematic)
    frame_ms = 1000 * sum(took) / frames

    per = 1e6 / frames / max(replayed, 1.0)  # seconds in all frames -> us a creature-frame

    def split(buckets: dict[str, list[float]]) -> dict[str, dict[str, float]]:
        out = {}
        for name, b in buckets.items():
            out[name] = {"ms": 1000 * b[0] / frames, "us_per_replayed": per * b[0]}
            if len(b) > 1:
                out[name]["cpu_us_per_replayed"] = per * b[1]
        return out

    rest_ms = frame_ms - 1000 * parts["stepping"][0] / frames
    rest_cpu = sum(cpu) - parts["stepping"][1]
    return {
        "creatures": crowd,
        "threads": threads,
        "build_s": build_s,
        "frames": frames,
        "replayed": replayed,
        "frame_ms": frame_ms,
        "frame_less_stepping_ms": rest_ms,
        "us_per_replayed_less_stepping": 1000 * rest_ms / max(replayed, 1.0),
        # the main thread's CPU time: what the machine's load changes least
        "cpu_us_per_replayed_less_stepping": per * rest_cpu,
        "systems": split(systems),
        "parts": split(parts),
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--crowd", type=int, default=10000)
    parser.add_argument("--frames", type=int, default=60)
    # 1.5 s, as `bench`: the timed frames start after the replayed creatures' fur strands
    # came to rest (a second unread, `fur.systems.rig.UNREAD_SECONDS`)
    parser.add_argument("--warmup", type=int, default=90)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--reduced", type=int, help="REDUCED budget (default: the scene's)")
    parser.add_argument("--json", action="store_true", help="one JSON object on stdout")
    args = parser.parse_args(argv)
    for name, least in (("crowd", 1), ("frames", 1), ("warmup", 0), ("threads", 1)):
        if getattr(args, name) < least:
            parser.error(f"--{name} must be >= {least}, got {getattr(args, name)}")
    if args.reduced is not None and args.reduced < 0:
        parser.error(f"--reduced must be >= 0, got {args.reduced}")
    result = run(args.crowd, args.frames, args.warmup, args.threads, args.seed, args.reduced)
    if args.json:
        print(json.dumps(result))
        return 0
    print(
        f"{result['creatures']} creatures, {result['replayed']:.0f} replayed, "
        f"{result['threads']} threads, built in {result['build_s']:.1f} s"
    )
    print(
        f"frame {result['frame_ms']:.1f} ms; less the stepping "
        f"{result['frame_less_stepping_ms']:.1f} ms = "
        f"{result['us_per_replayed_less_stepping']:.2f} us a replayed creature"
    )
    print(f"  main thread's CPU time: {result['cpu_us_per_replayed_less_stepping']:.2f} us")
    for group in ("systems", "parts"):
        print(f"{group}:")
        for name, row in sorted(result[group].items(), key=lambda kv: -kv[1]["ms"]):
            cpu = row.get("cpu_us_per_replayed")
            shown = "" if cpu is None else f" (CPU {cpu:.3f} us)"
            print(f"  {name:20s} {row['ms']:8.2f} ms {row['us_per_replayed']:7.3f} us{shown}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
