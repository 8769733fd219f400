"""Benchmark: milliseconds per sandbox frame, headless, split into simulate / upload / draw.

    python tools/bench_render.py                 # thesis_four_by_six and a 64-creature crowd
    python tools/bench_render.py --frames 60 --width 1280 --height 720 --json

`draw` ends with glFinish, so it includes the rasterising (llvmpipe on a machine
without a GPU). Medians over the measured frames, after a warm-up.
"""

from __future__ import annotations

import argparse
import json
import statistics
import time
from typing import Any

from ecs_tentacles.render import configure


def crowd(count: int) -> dict[str, Any]:
    """`count` 6-tentacle creatures on a square grid, each crawling to its right."""
    side = int(count**0.5 + 0.999)
    creatures = [
        {
            "name": f"c{i:03d}",
            "position": [1.6 * (i % side), 1.6 * (i // side)],
            "tentacles": {"count": 6},
            "goals": [{"position": [1.6 * (i % side) + 1.2, 1.6 * (i // side)]}],
        }
        for i in range(count)
    ]
    return {"version": 1, "name": f"crowd_{count}", "creatures": creatures}


def bench(scene: Any, name: str, frames: int, width: int, height: int) -> dict[str, Any]:
    from pyglet import gl

    from ecs_tentacles.render.sandbox import Sandbox

    sandbox = Sandbox(scene, width=width, height=height, headless=True)
    renderer = sandbox.renderer
    sandbox.step(30)
    timings: dict[str, list[float]] = {"simulate": [], "upload": [], "draw": []}
    for _ in range(frames):
        start = time.perf_counter()
        sandbox.step(1)
        simulated = time.perf_counter()
        renderer.upload()
        uploaded = time.perf_counter()
        renderer.draw()  # uploads again: subtract the measured upload below
        gl.glFinish()
        drawn = time.perf_counter()
        timings["simulate"].append(simulated - start)
        timings["upload"].append(uploaded - simulated)
        timings["draw"].append(drawn - uploaded - (uploaded - simulated))
    stats = {k: round(1000 * statistics.median(v), 3) for k, v in timings.items()}
    result = {
        "scene": name,
        "creatures": len(renderer.creature_entities),
        "links": len(renderer.link_rows),
        "width": width,
        "height": height,
        "frames": frames,
        "ms": stats,
        "draw_calls": renderer.draw_calls,
    }
    sandbox.close()
    return result


def main() -> None:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--frames", type=int, default=40)
    parser.add_argument("--width", type=int, default=1280)
    parser.add_argument("--height", type=int, default=720)
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    configure(headless=True)
    rows = [
        bench("thesis_four_by_six", "thesis_four_by_six", args.frames, args.width, args.height),
        bench(crowd(64), "crowd_64", args.frames, args.width, args.height),
    ]
    if args.json:
        print(json.dumps(rows, indent=2))
        return
    for row in rows:
        ms = row["ms"]
        print(
            f"{row['scene']} ({row['creatures']} creatures, {row['links']} links,"
            f" {row['width']}x{row['height']}, {row['draw_calls']} draw calls):"
            f" simulate {ms['simulate']:.2f} ms, upload {ms['upload']:.2f} ms,"
            f" draw {ms['draw']:.2f} ms"
        )


if __name__ == "__main__":
    main()
