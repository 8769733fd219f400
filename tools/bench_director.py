"""Benchmark: what directing a crowd costs, in one run (medians of repeats).

    python tools/bench_director.py                  # 256 creatures, 10 repeats
    python tools/bench_director.py --crowd 256 --repeats 20 --json
    python tools/bench_director.py --fur hedgehog   # every creature furred (500 guides)

* `spawn_ms`: `World.spawn` of one creature of a morphology the world has, into a
  running `crowd N --uniform` world (a model compiled for none of them);
  `spawn_new_model_ms`: of a morphology it has not (one model compiled);
* `despawn_ms`: `World.despawn` of a creature in the middle of the crowd;
* `scatter_100_ms`: the director's scatter of 100 creatures into the same world (taken
  out again between repeats);
* `frame_ms`: one physics frame of that world, for scale (2 threads);
* `--fur PRESET`: every creature of the crowd, and every one spawned or scattered,
  wears that fur preset with `--guides` guides (the rig's bind follows each change);
* sandbox, 64 creatures running (headless, 1280 x 720): `click_ms` (a goal click for a
  selection of 16, formation and undo record included), `place_ms` (a palette click
  and the frame that draws the newcomer), `frame_draw_ms` (one drawn frame); a click's
  change shows in the next drawn frame.

Progress on stderr; `--json` prints one object on stdout.
"""

from __future__ import annotations

import argparse
import copy
import json
import statistics
import sys
import time
from typing import Any

import numpy as np

from ecs_tentacles.render import configure


def _median_ms(samples: list[float]) -> float:
    return round(1e3 * statistics.median(samples), 2)


def world_costs(crowd: int, repeats: int, fur: dict[str, Any] | None = None) -> dict[str, Any]:
    from ecs_tentacles.creator.crowd import crowd_scene
    from ecs_tentacles.director.palette import presets
    from ecs_tentacles.director.scatter import scatter
    from ecs_tentacles.fur.stores import FurData
    from ecs_tentacles.world import World

    scene = crowd_scene(crowd, uniform=True)
    if fur is not None:
        for entry in scene["creatures"]:
            entry["fur"] = copy.deepcopy(fur)
    with World.from_scene(scene, threads=2, lod=False) as world:
        world.step(5)
        known = dict(copy.deepcopy(next(iter(world.creature_specs.values()))))
        for key in ("goals", "position", "heading_deg"):
            known.pop(key, None)
        spawn, fresh, despawn, frame = [], [], [], []
        for i in range(repeats):
            start = time.perf_counter()
            world.spawn(known, position=(500.0 + 10 * i, 500.0))
            spawn.append(time.perf_counter() - start)
            shape: dict[str, Any] = {
                "name": f"new{i}",
                "tentacles": {"count": 3 + i % 5, "links": 3 + i},
            }
            if fur is not None:
                shape["fur"] = copy.deepcopy(fur)
            start = time.perf_counter()
            world.spawn(shape, position=(500.0 + 10 * i, 520.0))
            fresh.append(time.perf_counter() - start)
            start = time.perf_counter()
            world.step(1)
            frame.append(time.perf_counter() - start)
        middle = sorted(world.creature_specs)[crowd // 4 : crowd // 4 + repeats]
        for entity in middle:
            start = time.perf_counter()
            world.despawn(entity)
            despawn.append(time.perf_counter() - start)
            world.step(1)
        print(f"spawn/despawn measured in a {crowd}-creature world", file=sys.stderr)
        octopus = presets()[0].creature()
        if fur is not None:
            octopus["fur"] = copy.deepcopy(fur)
        scattered = []
        for r in range(max(1, repeats // 3)):  # each into the same crowd: taken out after
            start = time.perf_counter()
            made = scatter(world, octopus, (-400.0, -400.0), 40.0, 100, seed=r)
            scattered.append(time.perf_counter() - start)
            assert len(made) == 100, len(made)
            for entity in made:
                world.despawn(entity)
        return {
            "crowd": crowd,
            "fur_guides": len(world.resource(FurData).guides) if fur is not None else 0,
            "spawn_ms": _median_ms(spawn),
            "spawn_new_model_ms": _median_ms(fresh),
            "despawn_ms": _median_ms(despawn),
            "scatter_100_ms": _median_ms(scattered),
            "frame_ms": _median_ms(frame),
        }


def sandbox_costs(repeats: int) -> dict[str, Any]:
    from pyglet.event import EventDispatcher
    from pyglet.window import mouse

    from ecs_tentacles.creator.crowd import crowd_scene
    from ecs_tentacles.director.panel import DirectorPanel
    from ecs_tentacles.locomotion.goals import GoalBook
    from ecs_tentacles.render.sandbox import Sandbox

    sandbox = Sandbox(crowd_scene(64, uniform=True), width=1280, height=720, headless=True)
    world, camera = sandbox.world, sandbox.renderer.camera
    sandbox.step(10)
    chosen = sorted(world.creature_specs)[:16]
    clicks, places, draws = [], [], []

    def press(at: Any) -> None:
        x, y = (round(float(v)) for v in camera.project(np.asarray(at, dtype=float)[None])[0])
        EventDispatcher.dispatch_event(sandbox.window, "on_mouse_press", x, y, mouse.LEFT, 0)
        EventDispatcher.dispatch_event(sandbox.window, "on_mouse_release", x, y, mouse.LEFT, 0)

    for i in range(repeats):
        sandbox.select_many(chosen)
        version = world.resource(GoalBook).version
        start = time.perf_counter()
        press([2.0 * i, -6.0, 0.0])
        clicks.append(time.perf_counter() - start)
        assert world.resource(GoalBook).version > version  # the goals changed at once
        start = time.perf_counter()
        sandbox.render()
        draws.append(time.perf_counter() - start)
        panel = sandbox.panel("Director")
        assert isinstance(panel, DirectorPanel)
        panel.placing = True
        sandbox.select(None)
        start = time.perf_counter()
        press([-20.0 - 3.0 * i, 20.0, 0.0])
        sandbox.render()  # the newcomer drawn: input to visible change
        places.append(time.perf_counter() - start)
        panel.placing = False
        sandbox.step(1)
    sandbox.close()
    return {
        "sandbox_creatures": 64,
        "click_ms": _median_ms(clicks),
        "place_ms": _median_ms(places),
        "frame_draw_ms": _median_ms(draws),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--crowd", type=int, default=256, help="creatures running (default 256)")
    parser.add_argument("--repeats", type=int, default=10, help="samples per figure (default 10)")
    parser.add_argument("--json", action="store_true", help="one JSON object on stdout")
    parser.add_argument("--fur", metavar="PRESET", help="every creature wears this fur preset")
    parser.add_argument("--guides", type=int, default=500, help="guides per fur (default 500)")
    args = parser.parse_args()
    if not 2 <= args.crowd <= 4096 or not 1 <= args.repeats <= 200:
        parser.error("--crowd must be in [2, 4096] and --repeats in [1, 200]")
    fur = None
    if args.fur is not None:
        from ecs_tentacles.fur.presets import preset_names

        if args.fur not in preset_names():
            parser.error(f"--fur must be one of {', '.join(preset_names())}, got {args.fur!r}")
        if not 1 <= args.guides <= 20000:
            parser.error(f"--guides must be in [1, 20000], got {args.guides}")
        fur = {"preset": args.fur, "groom": {"count": args.guides, "seed": 1}}
    configure(headless=True)
    figures = {**world_costs(args.crowd, args.repeats, fur), **sandbox_costs(args.repeats)}
    if args.json:
        print(json.dumps(figures))
    else:
        for name, value in figures.items():
            print(f"{name:>20}: {value}")


if __name__ == "__main__":
    main()
