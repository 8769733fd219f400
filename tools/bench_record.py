"""Benchmark: what recording a frame into a take costs, against a live frame, by crowd size.

    python tools/bench_record.py                          # 64 and 1,024 uniform creatures
    python tools/bench_record.py --creatures 64 --frames 30 --json
    python tools/bench_record.py --creatures 1024 --bakes  # and the bake-to-bake difference

One row per crowd (`ecs-tentacles crowd N --uniform --seed 3`): the median live frame
(`world.step()`), the median recorded frame (`TakeRecorder.capture()` right after it, the
record system's whole work; its plugins' tracks included: goals and fur guides), the
Python calls a recorded frame makes (the same at every size: no per-creature Python), and
what handing the take over costs at the end (`finish()`, as a bake does: the frames are
not copied, the tracks' frames are stacked).
`--bakes` also bakes the scene for `--seconds` at the simulation's rate and at a tenth of
it (`export.bake.bake`): the wall-time difference over the frame-count difference is what
a recorded frame costs a bake, everything but writing the take included.

On cb9ca9a a recorded frame of the 1,024 crowd cost about 127 ms (a bake at 60 fps
against the same at 30 fps), more than five live frames.
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
        live, recorded = [], []
        for _ in range(frames):
            gc.collect()
            start = time.perf_counter()
            world.step()
            middle = time.perf_counter()
            recorder.capture()
            live.append(middle - start)
            recorded.append(time.perf_counter() - middle)
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
            f" (fastest {row['recorded_frame_min_ms']:.2f})"
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
