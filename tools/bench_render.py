"""Benchmark: milliseconds per sandbox frame, headless, split into simulate / upload / draw.

    python tools/bench_render.py                 # thesis_four_by_six and a 64-creature crowd
    python tools/bench_render.py --frames 60 --width 1280 --height 720 --json
    python tools/bench_render.py --only fur_1k     # 1,000 guides x 10 children as ribbons

`draw` ends with glFinish, so it includes the rasterising (llvmpipe on a machine
without a GPU); `strands` is the fur's part of it (guides and child hairs as lit
ribbons, drawn again alone; the fur plugin uploads them in its draw hook, so `upload`
is the renderer's own arrays). Medians over the measured frames, after a warm-up.
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


def furry(guides: int, children: int) -> dict[str, Any]:
    """One cat-furred creature with `guides` guides of 8 points and `children` each."""
    fur = {"preset": "cat", "groom": {"count": guides, "points": 8}, "children": children}
    creature = {"name": "cat", "tentacles": {"count": 6}, "fur": fur}
    return {"version": 1, "name": f"fur_{guides}", "creatures": [creature]}


def bench(scene: Any, name: str, frames: int, width: int, height: int) -> dict[str, Any]:
    from pyglet import gl

    from ecs_tentacles.fur.render.strands import STRANDS, FurStrands
    from ecs_tentacles.render.sandbox import Sandbox

    sandbox = Sandbox(scene, width=width, height=height, headless=True)
    sandbox.hud.visible = False
    renderer = sandbox.renderer
    renderer.camera.shift_x = 0.0
    sandbox.step(30)
    timings: dict[str, list[float]] = {"simulate": [], "upload": [], "draw": [], "strands": []}
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
        renderer.target.bind()
        strands = renderer.state.get(STRANDS)  # the fur plugin's GL objects, if it drew fur
        start = time.perf_counter()
        if isinstance(strands, FurStrands):
            strands.draw(renderer.render_view)
        gl.glFinish()
        timings["strands"].append(time.perf_counter() - start)
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
        "strands": strands.guides.shape[0] + strands.children.shape[0]
        if isinstance(strands, FurStrands)
        else 0,
    }
    sandbox.close()
    return result


def main() -> None:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--frames", type=int, default=40)
    parser.add_argument("--width", type=int, default=1280)
    parser.add_argument("--height", type=int, default=720)
    parser.add_argument("--json", action="store_true")
    scenes = {
        "thesis_four_by_six": lambda: "thesis_four_by_six",
        "crowd_64": lambda: crowd(64),
        "fur_1k": lambda: furry(1000, 10),
    }
    parser.add_argument("--only", choices=sorted(scenes), nargs="*", default=sorted(scenes))
    args = parser.parse_args()
    configure(headless=True)
    rows = [bench(scenes[name](), name, args.frames, args.width, args.height) for name in args.only]
    if args.json:
        print(json.dumps(rows, indent=2))
        return
    for row in rows:
        ms = row["ms"]
        print(
            f"{row['scene']} ({row['creatures']} creatures, {row['links']} links,"
            f" {row['strands']} strands, {row['width']}x{row['height']},"
            f" {row['draw_calls']} draw calls):"
            f" simulate {ms['simulate']:.2f} ms, upload {ms['upload']:.2f} ms,"
            f" draw {ms['draw']:.2f} ms (strands {ms['strands']:.2f} ms)"
        )


if __name__ == "__main__":
    main()
