"""Benchmark: what child hairs cost the sandbox: their setup (`fur.children.layout`: roots
on the skin, the 3 nearest guides of each) and one frame of them (`interpolated_children`
at the sandbox's 3 points per child), for one creature with a big groom.

    python tools/bench_children.py                        # the guide budget, 4 children each
    python tools/bench_children.py --guides 100000 --children 1 --json

Peak memory is what numpy allocated above the built world (tracemalloc). On cb9ca9a the
nearest guides were found by brute force, 2,048 children at a time against every guide:
100,000 guides with a child each took 396 s and 9.8 GB of peak RSS; a k-d tree takes 0.4 s.
"""

from __future__ import annotations

import argparse
import json
import time
import tracemalloc
from typing import Any

from ecs_tentacles.fur.checks import MAX_SCENE_GUIDES
from ecs_tentacles.fur.children import interpolated_children, layout
from ecs_tentacles.world import World


def bench(guides: int, children: int, points: int) -> dict[str, Any]:
    """Seconds and peak MB of the children's setup and of one frame of them."""
    fur = {"groom": {"count": guides, "points": points}, "children": children}
    creature = {"name": "c", "tentacles": {"count": 3, "links": 2}, "fur": fur}
    start = time.perf_counter()
    world = World.from_scene({"version": 1, "creatures": [creature]})
    built = time.perf_counter() - start
    try:
        tracemalloc.start()
        start = time.perf_counter()
        made = layout(world)
        setup = time.perf_counter() - start
        setup_peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.reset_peak()
        start = time.perf_counter()
        interpolated_children(world, made, 3)
        frame = time.perf_counter() - start
        frame_peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
    finally:
        world.close()
    return {
        "guides": guides,
        "children": len(made.parent),
        "build_s": round(built, 2),
        "setup_s": round(setup, 2),
        "setup_peak_mb": round(setup_peak / 1e6),
        "frame_s": round(frame, 3),
        "frame_peak_mb": round(frame_peak / 1e6),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--guides", type=int, default=MAX_SCENE_GUIDES)
    parser.add_argument("--children", type=int, default=4, help="child hairs per guide")
    parser.add_argument("--points", type=int, default=8, help="points per guide")
    parser.add_argument("--json", action="store_true", help="the row as JSON")
    args = parser.parse_args()
    row = bench(args.guides, args.children, args.points)
    print(json.dumps(row) if args.json else "  ".join(f"{k} {v}" for k, v in row.items()))


if __name__ == "__main__":
    main()
