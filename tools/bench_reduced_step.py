"""Benchmark: what the framework adds to a reduced creature's step, against MuJoCo alone.

    python tools/bench_reduced_step.py                    # 1,024 uniform octopuses
    python tools/bench_reduced_step.py --crowd 1024 --varied --repeats 21 --json

Builds `ecs-tentacles crowd N` (`--uniform` unless `--varied`: the crowds `bench --crowd
N` runs) on one thread, steps `--warmup` frames, and captures the next frame's stepping
inputs (`physics.bare.capture`). Then, `--repeats` times, every batch's REDUCED rows go
through their framework step (`Batch.step_rows`: inputs pulled, servos formed, overlay,
MuJoCo's step, warnings and contacts kept, states shown, poses by forward kinematics)
from the same saved rows, and through MuJoCo alone on the captured inputs
(`physics.bare.step_captured`: overlay, `mj_setState`, `mj_step`, `mj_getState`).
Prints the medians and the framework's microseconds a reduced creature, and the show
step's forward kinematics alone: the numba kernel (`physics.pose_kernels`) against
MuJoCo's `mj_kinematics` row by row. Times are the thread's CPU time, which a shared
machine's load changes far less than wall time; state the load (`uptime`) anyway.
"""

from __future__ import annotations

import argparse
import json
import statistics
import time
from typing import Any

import mujoco
import numpy as np

from ecs_tentacles.creator.crowd import crowd_scene
from ecs_tentacles.physics import poses
from ecs_tentacles.physics.bare import capture, step_captured
from ecs_tentacles.physics.state_layout import S
from ecs_tentacles.physics.stepping import Work, plan
from ecs_tentacles.physics.tiers import FULL, REDUCED, reduced_substeps
from ecs_tentacles.world import World

SAVED = ("state", "rstate", "rsource", "xpos", "xquat", "warnings", "deepest", "step_cost")


def _cpu(call: Any, repeats: int, before: Any = None) -> float:
    """The median of `repeats` calls' CPU seconds (`before()` untimed ahead of each)."""
    took = []
    for _ in range(repeats):
        if before is not None:
            before()
        began = time.thread_time()
        call()
        took.append(time.thread_time() - began)
    return statistics.median(took)


def run(crowd: int, uniform: bool, warmup: int, repeats: int, seed: int) -> dict[str, Any]:
    """Build the crowd, time it, and return the figures (see the module doc)."""
    world = World.from_scene(crowd_scene(crowd, seed=seed, uniform=uniform), threads=1)
    try:
        world.step(warmup)
        physics = world.physics
        frame = capture(physics)
        substeps = world.settings.substeps
        steps = {FULL: substeps, REDUCED: reduced_substeps(substeps)}
        reduced = frame.active & (frame.tier == REDUCED)  # per creature
        found = [(batch, np.flatnonzero(reduced[batch.members])) for batch in physics.batches]
        stepped = [(batch, rows) for batch, rows in found if len(rows)]
        count = sum(len(rows) for _, rows in stepped)
        saved = [{name: getattr(batch, name).copy() for name in SAVED} for batch, _ in stepped]

        def restore() -> None:
            for (batch, _), arrays in zip(stepped, saved, strict=True):
                for name, values in arrays.items():
                    getattr(batch, name)[:] = values

        def framework() -> None:
            for batch, rows in stepped:
                batch.step_rows(rows, steps[REDUCED], 0, REDUCED)

        segments = plan(physics.batches, reduced, frame.tier, 1)

        def bare() -> None:
            step_captured(Work(segments, 1), frame, steps, 0)

        framework_s = _cpu(framework, repeats, restore)
        bare_s = _cpu(bare, repeats)
        restore()
        shows = {}
        for backend in ("auto", "numpy"):  # the kernel, then MuJoCo row by row
            poses.KERNELS.backend = backend

            def show() -> None:
                for batch, rows in stepped:
                    assert batch.pose_map is not None
                    full = batch.scratch_for(0, FULL)
                    batch.pose_map.show(rows, batch.state, batch.slices[int(S.mjSTATE_QPOS)],
                                        batch.xpos, batch.xquat, full.model, full.data)  # fmt: skip

            show()  # (the kernel compiled or loaded first)
            shows[backend] = _cpu(show, repeats)
        poses.KERNELS.backend = "auto"
    finally:
        world.close()
    per = 1e6 / max(count, 1)
    return {
        "creatures": crowd,
        "uniform": uniform,
        "reduced": count,
        "repeats": repeats,
        "mujoco_version": mujoco.__version__,
        "framework_ms": 1000 * framework_s,
        "bare_ms": 1000 * bare_s,
        "ratio": framework_s / bare_s if bare_s > 0 else float("inf"),
        "framework_us_per_reduced": per * (framework_s - bare_s),
        "show_kernel_us_per_reduced": per * shows["auto"],
        "show_mujoco_us_per_reduced": per * shows["numpy"],
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--crowd", type=int, default=1024)
    parser.add_argument("--varied", action="store_true", help="8 body plans, not uniform")
    parser.add_argument("--warmup", type=int, default=30)
    parser.add_argument("--repeats", type=int, default=15)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--json", action="store_true", help="one JSON object on stdout")
    args = parser.parse_args(argv)
    for name, least in (("crowd", 1), ("warmup", 0), ("repeats", 1)):
        if getattr(args, name) < least:
            parser.error(f"--{name} must be >= {least}, got {getattr(args, name)}")
    result = run(args.crowd, not args.varied, args.warmup, args.repeats, args.seed)
    if args.json:
        print(json.dumps(result))
        return 0
    kind = "uniform" if result["uniform"] else "varied"
    print(f"{result['creatures']} {kind} creatures, {result['reduced']} reduced, 1 thread (CPU)")
    print(
        f"  reduced step: framework {result['framework_ms']:.2f} ms, MuJoCo alone"
        f" {result['bare_ms']:.2f} ms ({result['ratio']:.3f}x):"
        f" {result['framework_us_per_reduced']:.1f} us a reduced creature"
    )
    print(
        f"  show step's kinematics: kernel {result['show_kernel_us_per_reduced']:.1f} us,"
        f" mj_kinematics row by row {result['show_mujoco_us_per_reduced']:.1f} us a creature"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
