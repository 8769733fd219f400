"""Benchmark: where a crowd's memory is, once built and after some frames.

    python tools/crowd_memory.py                          # 10,000 uniform octopuses, 30 frames
    python tools/crowd_memory.py --crowd 1024 --frames 60 --objects --json

Builds `ecs-tentacles crowd N --uniform` in this process (`World.from_scene`, 2 threads)
and reports the resident memory (psutil) and CPU seconds once built and after `--frames`
frames, the peak, and the largest numpy arrays reachable from the world by attribute
path, by their resident bytes (`physics.heap.resident_bytes`: the pages touched), with
their allocated bytes beside. With `--objects`, Python's tracked objects by type as well (the
collector's frozen objects included; slow at 10,000). One run: state the machine's
load (`uptime`); the resident figures move little with it, the seconds do.
"""

from __future__ import annotations

import argparse
import collections
import gc
import json
import os
import resource
import sys
import time
from typing import Any

import numpy as np
import psutil

from ecs_tentacles.creator.crowd import crowd_scene
from ecs_tentacles.options import WorldOptions
from ecs_tentacles.physics import heap
from ecs_tentacles.world import World

DEPTH = 9  # attribute path parts kept in a label


def arrays_by_path(root: object, top: int) -> list[tuple[str, float, float]]:
    """The `top` most resident owned numpy arrays reachable from `root`: (label, resident
    MB, allocated MB), by the first attribute path found (a list or dict of many items
    is one label)."""
    seen: set[int] = set()
    owners: collections.Counter[str] = collections.Counter()
    resident: collections.Counter[str] = collections.Counter()
    stack: list[tuple[Any, str, int]] = [(root, "world", 0)]
    while stack:
        obj, path, depth = stack.pop()
        if id(obj) in seen or isinstance(obj, (str, bytes, int, float, bool, type(None))):
            continue
        seen.add(id(obj))
        if isinstance(obj, np.ndarray):
            base = obj
            while isinstance(base.base, np.ndarray):
                base = base.base
            if base is obj or id(base) not in seen:
                seen.add(id(base))
                label = ".".join(path.split(".")[:DEPTH])
                owners[label] += base.nbytes
                resident[label] += heap.resident_bytes(base) or 0
            continue
        if depth > DEPTH:
            continue
        if isinstance(obj, dict):
            many = len(obj) > 50
            for key, value in obj.items():
                label = f"[{type(key).__name__}]" if many else str(key)
                stack.append((value, f"{path}.{label}", depth + 1))
        elif isinstance(obj, (list, tuple, set, frozenset, collections.deque)):
            many = len(obj) > 20
            for i, value in enumerate(obj):
                stack.append((value, f"{path}.[{'i' if many else i}]", depth + 1))
        else:
            for key, value in getattr(obj, "__dict__", {}).items():
                stack.append((value, f"{path}.{key}", depth + 1))
            for key in getattr(type(obj), "__slots__", ()):
                if hasattr(obj, key):
                    stack.append((getattr(obj, key), f"{path}.{key}", depth + 1))
    return [(label, size / 1e6, owners[label] / 1e6) for label, size in resident.most_common(top)]


def objects_by_type(top: int) -> list[tuple[str, int, float]]:
    """The `top` types of tracked Python objects by their own size: (name, count, MB)."""
    gc.unfreeze()  # frozen objects are not listed otherwise
    try:
        found = gc.get_objects()
        counts: collections.Counter[str] = collections.Counter()
        sizes: collections.Counter[str] = collections.Counter()
        for obj in found:
            name = type(obj).__name__
            counts[name] += 1
            sizes[name] += sys.getsizeof(obj)
    finally:
        gc.freeze()
    return [(name, counts[name], size / 1e6) for name, size in sizes.most_common(top)]


def measure(crowd: int, frames: int, objects: bool, top: int) -> dict[str, Any]:
    process = psutil.Process()

    def resident() -> float:
        return round(process.memory_info().rss / 2**20, 1)

    scene = crowd_scene(crowd, uniform=True)
    result: dict[str, Any] = {"crowd": crowd, "frames": frames, "load": os.getloadavg()[0]}
    cpu, wall = time.process_time(), time.perf_counter()
    world = World.from_scene(scene, WorldOptions(threads=2))
    try:
        result["build_cpu_s"] = round(time.process_time() - cpu, 2)
        result["build_wall_s"] = round(time.perf_counter() - wall, 2)
        result["built_rss_mib"] = resident()
        cpu = time.process_time()
        world.step(frames)
        result["frames_cpu_s"] = round(time.process_time() - cpu, 2)
        result["rss_mib"] = resident()
        result["peak_mib"] = round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024, 1)
        result["tiers"] = world.lod.counts()
        result["arrays_mb"] = arrays_by_path(world, top)
        if objects:
            result["objects"] = objects_by_type(top)
    finally:
        world.close()
    return result


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--crowd", type=int, default=10_000, help="creatures (default 10,000)")
    parser.add_argument("--frames", type=int, default=30, help="frames after the build (30)")
    parser.add_argument("--top", type=int, default=25, help="largest arrays and types listed")
    parser.add_argument("--objects", action="store_true", help="Python objects by type too")
    parser.add_argument("--json", action="store_true", help="one JSON object")
    args = parser.parse_args(argv)
    for name, least in (("crowd", 1), ("frames", 0), ("top", 0)):
        if getattr(args, name) < least:
            parser.error(f"--{name} must be >= {least}, got {getattr(args, name)}")  # exit 2
    result = measure(args.crowd, args.frames, args.objects, args.top)
    if args.json:
        print(json.dumps(result))
        return 0
    print(
        f"{result['crowd']} uniform (load {result['load']:.1f}): built in"
        f" {result['build_cpu_s']} s CPU ({result['build_wall_s']} s wall),"
        f" {result['built_rss_mib']} MiB; after {result['frames']} frames"
        f" ({result['frames_cpu_s']} s CPU) {result['rss_mib']} MiB, peak"
        f" {result['peak_mib']} MiB; tiers {result['tiers']}"
    )
    print("  resident  allocated (MB)")
    for label, mb, allocated in result["arrays_mb"]:
        print(f"  {mb:8.1f} {allocated:8.1f}  {label}")
    for name, count, mb in result.get("objects", []):
        print(f"  {mb:8.1f} MB  {count:9d} {name}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
