"""Benchmark: cost of a headless frame versus MuJoCo stepping the same model alone.

    python tools/bench_frame.py                      # the bundled scenes
    python tools/bench_frame.py octopus --frames 300 --repeats 7 --json

For each scene, alternates (in swapping order) `world.step(frames)` with raw
`mujoco.mj_step(m, d, nstep=substeps)` x frames on a copy of the same model and state
(both follow the same trajectory, checked), and prints the median ms per frame of
each, the overhead, and the framework's own per-frame work (control and sucker
writes, pose sync) timed alone, which is steadier on a shared machine.
"""

from __future__ import annotations

import argparse
import json
import statistics
import time
import timeit

import mujoco

from ecs_tentacles.scene.load import bundled_scene_names
from ecs_tentacles.world import World


def bench_scene(scene: str, frames: int, repeats: int) -> dict[str, object]:
    """Median ms per frame for the framework and for bare MuJoCo, interleaved."""
    world = World.from_scene(scene)
    world.step(frames)  # settle, warm caches
    model = world.physics.model
    raw = mujoco.MjData(model)
    mujoco.mj_copyData(raw, model, world.physics.data)
    substeps = world.settings.substeps
    framework: list[float] = []
    bare: list[float] = []
    for repeat in range(repeats):
        for which in (0, 1) if repeat % 2 else (1, 0):
            start = time.perf_counter()
            if which == 0:
                world.step(frames)
            else:
                for _ in range(frames):
                    mujoco.mj_step(model, raw, nstep=substeps)
            (framework if which == 0 else bare).append(
                (time.perf_counter() - start) * 1000 / frames
            )
    if not (raw.qpos == world.physics.data.qpos).all():
        raise RuntimeError(f"{scene}: framework and bare MuJoCo diverged; the comparison is void")
    own = _own_work_us(world)
    world.close()
    ours, theirs = statistics.median(framework), statistics.median(bare)
    return {
        "scene": scene,
        "frames": frames,
        "repeats": repeats,
        "framework_ms_per_frame": round(ours, 4),
        "mujoco_ms_per_frame": round(theirs, 4),
        "overhead_percent": round(100 * (ours - theirs) / theirs, 2),
        "own_work_us_per_frame": round(own, 2),
        "own_work_percent": round(100 * own / 1000 / theirs, 2),
    }


def _own_work_us(world: World, number: int = 2000) -> float:
    """Median microseconds of the framework's per-frame array work, without stepping."""
    backend = world.physics

    def work() -> None:
        backend.write_controls(world.motors)
        backend.write_suckers(world.suckers)
        world.schedule.substep_systems()
        backend.sync(world.transforms)

    return statistics.median(timeit.timeit(work, number=number) / number * 1e6 for _ in range(5))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "scenes", nargs="*", help="scene files or bundled names (default: all bundled)"
    )
    parser.add_argument("--frames", type=int, default=120)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    rows = [bench_scene(s, args.frames, args.repeats) for s in args.scenes or bundled_scene_names()]
    if args.json:
        print(json.dumps(rows, indent=2))
        return
    print(
        f"{'scene':<20} {'ecs_tentacles ms':>16} {'mujoco ms':>10} {'overhead':>9}"
        f" {'own work us':>12} {'own work':>9}"
    )
    for row in rows:
        print(
            f"{row['scene']:<20} {row['framework_ms_per_frame']:>16.3f}"
            f" {row['mujoco_ms_per_frame']:>10.3f} {row['overhead_percent']:>8.1f}%"
            f" {row['own_work_us_per_frame']:>12.1f} {row['own_work_percent']:>8.2f}%"
        )


if __name__ == "__main__":
    main()
