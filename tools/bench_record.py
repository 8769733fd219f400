"""Benchmark: what recording a frame into a take costs, against a live frame, by crowd size.

    python tools/bench_record.py                          # 64 and 1,024 uniform creatures
    python tools/bench_record.py --creatures 64 --frames 30 --json
    python tools/bench_record.py --creatures 1024 --bakes  # and the bake-to-bake difference

One row per crowd (`ecs-tentacles crowd N --uniform --seed 3`): the median live frame
(`world.step()`), the median recorded frame (`TakeRecorder.capture()` right after it, the
record system's whole work; its plugins' tracks included: goals and fur guides), the
Python calls a recorded frame makes (the same at every size: no per-creature Python), and
what handing the take over costs at the end (`finish()`, as a bake does: nothing is
copied). Beside it, a plain copy of the frame's body poses into memory no page of which
was touched before, as every frame of a take held in memory is: on a virtual machine the
first touch of fresh pages can cost more than the copy (a take streamed through a reused
buffer would not pay it).
`--bakes` also bakes the scene for `--seconds` at the simulation's rate and at a tenth of
it (`export.bake.bake`): the wall-time difference over the frame-count difference is what
a recorded frame costs a bake, everything but writing the take included.

On cb9ca9a a recorded frame of the 1,024 crowd seemed to cost about 127 ms (a bake at 60
fps against the same at 30 fps). Most of that is writing the take, not recording it:
deflating 3.4 MB a frame into the npz took 125 ms a frame (7.65 s for 61 frames) and
checking the take before writing 32. Recording itself, measured here (one run each, load
1.6): 7.0 ms a frame (fastest 3.9) and a 0.62 s copy of the frames at the end, now 1.5
ms (fastest 1.0; 3.7 % of a live frame) and nothing copied; 64 creatures 0.50 -> 0.31 ms.
"""

from __future__ import annotations

import argparse
import gc
import json
import statistics
import sys
import time
from collections.abc import Callable
from typing import Any

import numpy as np

from ecs_tentacles.creator.crowd import crowd_scene
from ecs_tentacles.export.bake import BakePlan, bake
from ecs_tentacles.export.recording import TakeRecorder, before_recording
from ecs_tentacles.world import World


def python_calls(action: Callable[[], object]) -> int:
    """Python function calls made while `action` runs (as the tests count them), the
    cyclic garbage collector held off (its callbacks are not the action's calls)."""
    count = 0

    def profile(frame: object, event: str, arg: object) -> None:
        nonlocal count
        count += event == "call"

    gc.collect()
    gc.disable()
    sys.setprofile(profile)
    try:
        action()
    finally:
        sys.setprofile(None)
        gc.enable()
    return count


def bench(creatures: int, frames: int, seed: int = 3) -> dict[str, Any]:
    """Median milliseconds of a live frame and of a recorded frame (capture after that
    step) over `frames` frames of the uniform crowd; `finish()` once at the end."""
    scene = crowd_scene(creatures, seed, uniform=True)
    start = time.perf_counter()
    world = World.from_scene(scene)
    built = time.perf_counter() - start
    try:
        world.step(2)  # first-use caches out of the timings
        recorder = TakeRecorder(world, capacity=frames + 2)
        before_recording(world)
        recorder.capture()  # take frame 0: every locator appears
        live, recorded, fresh = [], [], []
        poses = world.transforms
        untouched = np.empty((frames, len(poses.pos), 7), np.float32)  # no page touched yet
        for k in range(frames):
            gc.collect()
            start = time.perf_counter()
            world.step()
            middle = time.perf_counter()
            recorder.capture()
            live.append(middle - start)
            recorded.append(time.perf_counter() - middle)
            start = time.perf_counter()
            untouched[k, :, :3], untouched[k, :, 3:] = poses.pos, poses.quat
            fresh.append(time.perf_counter() - start)
        world.step()
        calls = python_calls(recorder.capture)
        start = time.perf_counter()
        take = getattr(recorder, "finish", recorder.take)()  # take(): before finish() was
        handed = time.perf_counter() - start
    finally:
        world.close()
    arrays = take.arrays()
    frame_bytes = sum(a.nbytes for a in arrays.values() if a.shape[:1] == (take.frames,))
    live_ms, capture_ms = 1000 * statistics.median(live), 1000 * statistics.median(recorded)
    return {
        "creatures": creatures,
        "bodies": len(take.header["bodies"]),
        "build_s": round(built, 2),
        "live_frame_ms": round(live_ms, 2),
        "recorded_frame_ms": round(capture_ms, 3),
        "recorded_frame_min_ms": round(1000 * min(recorded), 3),  # the work, undisturbed
        "bodies_fresh_copy_ms": round(1000 * statistics.median(fresh), 3),
        "recorded_per_live": round(capture_ms / live_ms, 4),
        "recorded_frame_calls": calls,
        "finish_ms": round(1000 * handed, 1),
        "frame_mb": round(frame_bytes / take.frames / 1e6, 3),
    }


def bake_difference(creatures: int, seconds: float, seed: int = 3) -> dict[str, Any]:
    """Wall seconds of two bakes of the crowd, at the simulation's rate and at a tenth of
    it, and the milliseconds per recorded frame their difference makes. A first bake at a
    tenth goes untimed: it records the gait clips the crowd replays (once a process)."""
    scene = crowd_scene(creatures, seed, uniform=True)
    every = BakePlan.make(scene, seconds=seconds)
    tenth = BakePlan.make(scene, seconds=seconds, fps=every.sim_fps / 10)
    walls, counts = [], []
    for plan in (tenth, every, tenth):
        start = time.perf_counter()
        take = bake(plan, progress=False)
        walls.append(time.perf_counter() - start)
        counts.append(take.frames)
        del take
        gc.collect()
    per_frame = (walls[1] - walls[2]) / (counts[1] - counts[2])
    return {
        "bake_all_s": round(walls[1], 2),
        "bake_tenth_s": round(walls[2], 2),
        "bake_recorded_frame_ms": round(1000 * per_frame, 1),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--creatures", default="64,1024", help="crowd sizes, comma-separated")
    parser.add_argument("--frames", type=int, default=30, help="frames timed per crowd")
    parser.add_argument("--seed", type=int, default=3)
    parser.add_argument("--bakes", action="store_true", help="also the bake-to-bake difference")
    parser.add_argument("--seconds", type=float, default=1.0, help="simulated seconds per bake")
    parser.add_argument("--json", action="store_true", help="one JSON object per row")
    args = parser.parse_args()
    for creatures in (int(text) for text in args.creatures.split(",")):
        row = bench(creatures, args.frames, args.seed)
        if args.bakes:
            row.update(bake_difference(creatures, args.seconds, args.seed))
        if args.json:
            print(json.dumps(row), flush=True)
            continue
        line = (
            f"{creatures} creatures ({row['bodies']:,} bodies): live frame"
            f" {row['live_frame_ms']:.1f} ms, recorded frame {row['recorded_frame_ms']:.2f} ms"
            f" (fastest {row['recorded_frame_min_ms']:.2f}; the bodies copied into untouched"
            f" memory {row['bodies_fresh_copy_ms']:.2f})"
            f" ({100 * row['recorded_per_live']:.1f} % of a live frame,"
            f" {row['recorded_frame_calls']} Python calls, {row['frame_mb']:.2f} MB),"
            f" finish() {row['finish_ms']:.0f} ms"
        )
        if args.bakes:
            line += (
                f"; bakes {row['bake_all_s']:.1f} s vs {row['bake_tenth_s']:.1f} s:"
                f" {row['bake_recorded_frame_ms']:.1f} ms a recorded frame"
            )
        print(line, flush=True)


if __name__ == "__main__":
    main()
