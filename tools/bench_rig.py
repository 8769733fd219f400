"""Benchmark: fur rig evaluation time for 1k, 10k and 100k guides of 8 points.

    python tools/bench_rig.py                   # median ms, synthetic arrays and the system
    python tools/bench_rig.py --sizes 10000 --repeats 50 --json
    python tools/bench_rig.py --backend numpy   # without the numba kernels
    python tools/bench_rig.py --parallel off    # numba's serial kernels at every size
    python tools/bench_rig.py --clock cpu       # CPU time of all threads (a busy machine)

"math": `rig.evaluate` on synthetic arrays (every behaviour on: lift, aim, direction,
random twist), in the system's blocks, world frames and posed curves included;
"math+dynamic": the same plus the strand simulation on every guide; "system":
`Rig.process` in a world whose creature has a fur of n guides (all behaviours on,
controls moved, emotion off), with and without the dynamic behaviour. The backend is
numba's kernels when numba imports (the dev extra), else numpy (see `fur.rig`); the
numba kernels run on all cores from `rig.PARALLEL_GUIDES` guides ("auto"), or as told.
Targets on the 2-core machine: 10k <= 2 ms, 100k <= 16 ms.
"""

from __future__ import annotations

import argparse
import json
import statistics
import time
from collections.abc import Callable
from typing import Any

import numpy as np

from ecs_tentacles.fur import rig as rig_math
from ecs_tentacles.fur.blocks import BLOCK
from ecs_tentacles.fur.dynamics import Strands, blend_profile
from ecs_tentacles.fur.stores import FurData
from ecs_tentacles.fur.synthetic import synthetic_rig
from ecs_tentacles.world import World

POINTS = 8


CLOCK = time.perf_counter  # --clock cpu: time.process_time (all threads' CPU time)


def median_ms(func: Callable[[], Any], repeats: int) -> float:
    """Median time of `func` in milliseconds on `CLOCK` (after one warm-up call)."""
    func()
    times = []
    for _ in range(repeats):
        start = CLOCK()
        func()
        times.append(CLOCK() - start)
    return 1000 * statistics.median(times)


def bench_math(n: int, repeats: int, dynamic: bool) -> float:
    """Rig math on synthetic arrays (one body), optionally with strands on every guide."""
    bind, values = synthetic_rig(n, POINTS)
    rotation = np.eye(3)[None]
    position = np.zeros((1, 3))
    frames = np.zeros((n, 4, 3), dtype=np.float32)
    curves = np.zeros((n, POINTS, 3), dtype=np.float32)
    strands = Strands(
        guides=np.arange(n),
        segment=np.full((POINTS, n), 0.05 / (POINTS - 1), dtype=np.float32),
        pull=np.full(n, 0.1, dtype=np.float32),
        keep=np.full(n, 0.95, dtype=np.float32),
        gravity=np.tile(np.array([[0.0], [0.0], [-9.81 / 3600]], dtype=np.float32), (1, n)),
        profile=blend_profile(POINTS)[:, None, None],
    )
    weight = np.full(n, 0.6, dtype=np.float32)
    scratch = rig_math.RigBuffers()
    blocks = [(rows, bind.part(rows)) for rows in (slice(s, s + BLOCK) for s in range(0, n, BLOCK))]

    many = rig_math.use_parallel(n)

    def run() -> None:
        plan = rig_math.control_table(values)  # as `Rig.process` does: once a frame
        for rows, part in blocks:
            rig_math.evaluate(
                part, plan, rotation, position, frames[rows], curves[rows], scratch, many
            )
        if dynamic and not strands.step_kernel(curves, frames, bind.normal, weight, many):
            rig = np.ascontiguousarray(curves.transpose(1, 2, 0))
            out = strands.step(rig, frames[:, 3].T, bind.normal, weight)
            curves[...] = out.transpose(2, 0, 1)

    return median_ms(run, repeats)


def bench_system(n: int, repeats: int, dynamic: bool) -> float:
    """`Rig.process` in a world with one creature carrying n guides."""
    behaviours = ["lift", "aim", "direction", "random"] + (["dynamic"] if dynamic else [])
    control = {"name": "main", "lift": 0.3, "aim": 0.3, "direction": 0.3, "random": 0.5}
    control["dynamic"] = 0.6
    scene = {
        "version": 1,
        "creatures": [
            {
                "name": "furry",
                "tentacles": {"count": 3, "links": 2},
                "fur": {
                    "behaviours": behaviours,
                    "groom": {"count": n, "points": POINTS},
                    "controls": [control],
                },
            }
        ],
    }
    world = World.from_scene(scene, plugins={"locomotion": False, "suckers": False})
    world.step(1)
    world.resource(FurData).controls.position[0] += (
        0.02,
        0.0,
        0.01,
    )  # a moved control: direction works
    rig = world.schedule["rig"]
    result = median_ms(lambda: rig.process(world, world.settings.dt), repeats)
    world.close()
    return result


def main() -> None:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="*", default=[1_000, 10_000, 100_000])
    parser.add_argument("--repeats", type=int, default=30)
    parser.add_argument("--json", action="store_true")
    parser.add_argument("--backend", choices=["auto", "numpy"], default=rig_math.BACKEND)
    parser.add_argument("--parallel", choices=["auto", "on", "off"], default="auto")
    parser.add_argument("--clock", choices=["wall", "cpu"], default="wall")
    args = parser.parse_args()
    global CLOCK
    CLOCK = time.process_time if args.clock == "cpu" else time.perf_counter
    rig_math.BACKEND = args.backend
    rig_math.PARALLEL_GUIDES = {"auto": rig_math.PARALLEL_GUIDES, "on": 0, "off": 1 << 62}[
        args.parallel
    ]
    backend = "numba" if rig_math.kernels() is not None else "numpy"
    rows = []
    for n in args.sizes:
        repeats = max(5, args.repeats * 10_000 // max(n, 10_000))
        rows.append(
            {
                "guides": n,
                "points": POINTS,
                "backend": backend,
                "math_ms": round(bench_math(n, repeats, False), 3),
                "math_dynamic_ms": round(bench_math(n, repeats, True), 3),
                "system_ms": round(bench_system(n, repeats, False), 3),
                "system_dynamic_ms": round(bench_system(n, repeats, True), 3),
            }
        )
    if args.json:
        print(json.dumps(rows, indent=2))
        return
    print(f"backend: {backend}, parallel from {rig_math.PARALLEL_GUIDES} guides, {args.clock} ms")
    print(f"{'guides':>8} {'math':>9} {'+dynamic':>9} {'system':>9} {'+dynamic':>9}   (median ms)")
    for row in rows:
        print(
            f"{row['guides']:>8} {row['math_ms']:>9.3f} {row['math_dynamic_ms']:>9.3f}"
            f" {row['system_ms']:>9.3f} {row['system_dynamic_ms']:>9.3f}"
        )


if __name__ == "__main__":
    main()
