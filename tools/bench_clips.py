"""Benchmark: gait clips of the bundled octopus, recorded once, replayed for K creatures.

    python tools/bench_clips.py                      # K = 100, 1000, 10000; median us
    python tools/bench_clips.py --sizes 1000 --repeats 200 --json

Prints the recording cost (seconds for both clips of the morphology), the loops
(frames, recorded end-start mismatch, wrap step), and `GaitClips.evaluate` per
creature with interpolation (lerp + nlerp) and with the nearest frame, each the median
of `repeats` runs into preallocated output arrays.
"""

from __future__ import annotations

import argparse
import json
import statistics
import time
from typing import Any

import numpy as np

from ecs_tentacles.clips.clips import GaitClips
from ecs_tentacles.scene.load import load_scene, resolve_scene_path


def _evaluate_us(clips: GaitClips, k: int, repeats: int, interpolate: bool) -> float:
    rng = np.random.default_rng(0)
    kind = rng.integers(0, 2, k)
    phase = rng.uniform(0, 1000, k)
    xy = rng.uniform(-50, 50, (k, 2))
    heading = rng.uniform(-np.pi, np.pi, k)
    pos = np.empty((k, len(clips.bodies), 3))
    quat = np.empty((k, len(clips.bodies), 4))
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        clips.evaluate(kind, phase, xy, heading, pos, quat, interpolate=interpolate)
        times.append(time.perf_counter() - start)
    return 1e6 * statistics.median(times) / k


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[100, 1000, 10000])
    parser.add_argument("--repeats", type=int, default=50)
    parser.add_argument("--json", action="store_true", help="one JSON object on stdout")
    args = parser.parse_args()
    scene = load_scene(resolve_scene_path("octopus"))
    clips = GaitClips.record(scene["creatures"][0], scene["physics"])
    result: dict[str, Any] = {"bodies": len(clips.bodies), "record_s": clips.seconds, "clips": {}}
    for clip in (clips.idle, clips.crawl):
        steps = clip.steps()
        result["clips"][clip.kind] = {
            "frames": clip.frames,
            "speed_m_s": clip.speed,
            "mismatch_mm": 1000 * clip.mismatch,
            "wrap_step_mm": 1000 * float(steps[-1]),
            "largest_step_mm": 1000 * float(steps[:-1].max()),
        }
    result["evaluate_us_per_creature"] = {
        str(k): {
            "lerp": _evaluate_us(clips, k, args.repeats, True),
            "nearest": _evaluate_us(clips, k, args.repeats, False),
        }
        for k in args.sizes
    }
    if args.json:
        print(json.dumps(result))
        return
    print(f"octopus, {result['bodies']} bodies: both clips recorded in {clips.seconds:.2f} s")
    for kind, c in result["clips"].items():
        print(
            f"  {kind}: {c['frames']} frames, {c['speed_m_s']:.3f} m/s, mismatch"
            f" {c['mismatch_mm']:.1f} mm, wrap step {c['wrap_step_mm']:.1f} mm"
            f" (largest ordinary {c['largest_step_mm']:.1f} mm)"
        )
    for k, us in result["evaluate_us_per_creature"].items():
        print(f"  K={k}: {us['lerp']:.2f} us/creature (lerp), {us['nearest']:.2f} (nearest)")


if __name__ == "__main__":
    main()
