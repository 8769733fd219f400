"""Corner search: scenes with every numeric field at a schema bound, built and stepped.

    python tools/scene_corners.py                      # 1500 scenes, seed 0, 60 frames
    python tools/scene_corners.py --scenes 300 --seed 7 --json

Each scene is one creature (at most 3 tentacles of 4 links) whose every numeric
tentacle, mantle, locomotion and physics field is drawn from {lowest, highest, default,
a middle value} of its schema range, plus a gravity. A scene is either refused at load
(counted by the JSON path of its first problem) or built and stepped; an accepted
scene whose bodies turn non-finite or that makes MuJoCo warn is "unstable" and printed
whole. This is how the load-time physical checks (`ecs_tentacles.scene.physical`)
were found; the property test draws from the same schema with hypothesis instead.
"""

from __future__ import annotations

import argparse
import collections
import json
import random
from typing import Any

import mujoco
import numpy as np

from ecs_tentacles.scene.errors import SceneError
from ecs_tentacles.scene.schema import load_schema
from ecs_tentacles.world import World


def corner(spec: dict[str, Any], rng: random.Random) -> float | int:
    """A value at a corner of a numeric field's range (or its default or a middle value)."""
    low = spec.get("minimum", spec.get("exclusiveMinimum", 0.0))
    high = spec["maximum"]
    if "exclusiveMinimum" in spec:
        low = low * (1 + 1e-9) if low else 1e-12
    middle = (low * high) ** 0.5 if low > 0 else high / 2
    choice = rng.choices(["low", "high", "default", "middle"], weights=[1, 3, 4, 3])[0]
    value = {"low": low, "high": high, "default": spec.get("default", low), "middle": middle}
    if spec.get("type") == "integer":
        return int(value[choice])
    return float(value[choice])


def _numbers(properties: dict[str, Any], rng: random.Random) -> dict[str, Any]:
    return {
        key: corner(spec, rng)
        for key, spec in properties.items()
        if spec.get("type") in ("number", "integer") and "maximum" in spec
    }


def corner_scene(rng: random.Random) -> dict[str, Any]:
    """One creature and the physics with every numeric field at a corner."""
    schema = load_schema()
    creature = schema["$defs"]["creature"]["properties"]
    tentacles = _numbers(creature["tentacles"]["properties"], rng)
    tentacles["count"] = min(tentacles["count"], 3)
    tentacles["links"] = min(tentacles["links"], 4)
    tentacles["twist"] = rng.random() < 0.5
    tentacles["suckers"] = rng.choice(["tip", "every_link"])
    physics = _numbers(schema["properties"]["physics"]["properties"], rng)
    physics["gravity"] = [rng.choice([0, -3, 3, 0.5]) for _ in range(2)]
    physics["gravity"].append(rng.choice([-30, -9.81, -5]))
    goals = [{"position": [rng.uniform(-2, 2), rng.uniform(-2, 2)]}] if rng.random() < 0.7 else []
    return {
        "version": 1,
        "physics": physics,
        "creatures": [
            {
                "tentacles": tentacles,
                "mantle": _numbers(creature["mantle"]["properties"], rng),
                "locomotion": _numbers(creature["locomotion"]["properties"], rng),
                "goals": goals,
            }
        ],
    }


def search(scenes: int, seed: int, frames: int) -> dict[str, Any]:
    """Build and step `scenes` corner scenes; counts per outcome and the unstable scenes."""
    rng = random.Random(seed)
    counts: collections.Counter[str] = collections.Counter()
    unstable: list[dict[str, Any]] = []
    warnings: list[str] = []
    mujoco.set_mju_user_warning(warnings.append)
    try:
        for _ in range(scenes):
            scene = corner_scene(rng)
            warnings.clear()
            try:
                world = World.from_scene(scene)
            except SceneError as refused:
                counts["refused " + refused.problems[0].split(":")[0]] += 1
                continue
            world.step(frames)
            finite = bool(np.isfinite(world.transforms.pos).all())
            world.close()
            if warnings or not finite:
                counts["unstable"] += 1
                unstable.append({"scene": scene, "warning": warnings[:1], "finite": finite})
            else:
                counts["ok"] += 1
    finally:
        mujoco.set_mju_user_warning(None)
    return {"counts": dict(counts), "unstable": unstable}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--scenes", type=int, default=1500)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--frames", type=int, default=60)
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    args = parser.parse_args()
    result = search(args.scenes, args.seed, args.frames)
    if args.json:
        print(json.dumps(result))
        return
    for outcome, count in sorted(result["counts"].items(), key=lambda item: -item[1]):
        print(f"{count:6d}  {outcome}")
    for case in result["unstable"]:
        print(json.dumps(case))


if __name__ == "__main__":
    main()
