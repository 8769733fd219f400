"""Level-of-detail fidelity: the same crossing crowd with level of detail and with it off.

    python tools/lod_fidelity.py                      # 64 creatures, 20 s, both runs
    python tools/lod_fidelity.py --creatures 160 --seconds 10 --json
    python tools/lod_fidelity.py --goals-within 0.8   # goals near enough to arrive
    python tools/lod_fidelity.py --goals-within 0.8 --nudge 0.0001   # the floor: full vs full
    python tools/lod_fidelity.py --goals-within 0.8 --model links=1,gain=1,damping=1
    python tools/lod_fidelity.py --creatures 160 --seconds 10 --reduced 64   # a smaller budget

Runs `crowd_scene(N)` (every creature crawling across the crowd, so they meet) once with
the scene's level of detail (default budgets) and once with `lod=False` (everyone full),
in two processes, and compares what a crowd tool's user would notice:

* progress: how much closer to its goal each creature got (metres), the crowd's mean,
  and the ratio of the two runs' means (1.0: the same);
* goals: which creatures reached their goal, and how far apart (seconds) the same
  creature's arrival times are in the two runs (the crossing crowd's goals are across
  it, farther than 20 s of crawling: `--goals-within M` brings them nearer);
* interpenetration: the deepest overlap of two creatures' link capsules (sampled every
  `--every` frames: the capsules of creatures whose bodies come near, segment against
  segment), in millimetres;
* recoveries (physics blow-ups restored), the tiers at the end, promotions, wall time.

With `--nudge M` the first run is lod off too, with every creature's start moved M
metres along x: how far apart two full runs drift on their own, the floor any level of
detail is compared against. With `--model KEY=VALUE,...` the level-of-detail run's reduced
creatures take another reduced model (`tools/reduced_models.py`).
"""

from __future__ import annotations

import argparse
import json
import math
import time
from concurrent.futures import ProcessPoolExecutor
from typing import Any

import numpy as np
from reduced_models import model_settings, use_model

from ecs_tentacles.components import Creature, Link, Tentacle, Transform
from ecs_tentacles.creator.crowd import crowd_scene
from ecs_tentacles.numeric.quaternions import quat_rotate
from ecs_tentacles.physics.pairs import near_pairs
from ecs_tentacles.scene.overlap import segment_distances
from ecs_tentacles.world import World


def _capsules(world: World) -> tuple[list[np.ndarray], np.ndarray, np.ndarray]:
    """Per creature (store order) its links' Transform rows; every link's half length and
    radius, in that order."""
    rows, halves, radii = [], [], []
    for _, creature in sorted(world.query(Creature), key=lambda item: item[1].row):
        mine = []
        for tentacle in creature.tentacles:
            for link in world.component(tentacle, Tentacle).links:
                shape = world.component(link, Link)
                mine.append(world.component(link, Transform).row)
                halves.append(0.5 * shape.length)
                radii.append(shape.radius)
        rows.append(np.asarray(mine, dtype=np.int64))
    return rows, np.asarray(halves), np.asarray(radii)


def deepest_overlap(
    world: World, rows: list[np.ndarray], half: np.ndarray, radius: np.ndarray
) -> float:
    """The deepest overlap (m, >= 0) of two different creatures' link capsules now."""
    pos, quat = world.transforms.pos, world.transforms.quat
    centres = np.array([pos[r].mean(axis=0) for r in rows])
    reach = np.array(
        [np.linalg.norm(pos[r] - c, axis=1).max() + 0.2 for r, c in zip(rows, centres, strict=True)]
    )
    a, b = near_pairs(centres, reach, 0.0)
    starts = np.cumsum([0] + [len(r) for r in rows])
    deepest = 0.0
    for i, j in zip(a.tolist(), b.tolist(), strict=True):
        if i > j:
            continue
        ends = []
        for k in (i, j):
            link = slice(starts[k], starts[k + 1])
            axis = quat_rotate(quat[rows[k]], np.array([1.0, 0.0, 0.0])) * half[link, None]
            ends.append((pos[rows[k]] - axis, pos[rows[k]] + axis, radius[link]))
        (p1, q1, r1), (p2, q2, r2) = ends
        gap = (
            segment_distances(p1[:, None], q1[:, None], p2[None], q2[None]) - r1[:, None] - r2[None]
        )
        deepest = max(deepest, float(-gap.min()))
    return deepest


def goals_within(scene: dict[str, Any], metres: float) -> dict[str, Any]:
    """`scene` with every goal brought to at most `metres` from its creature's start, on
    the way to where it was (the crowd still crosses toward its middle, and creatures
    arrive within a run: their arrival times can be compared)."""
    for creature in scene["creatures"]:
        start = np.asarray(creature["position"][:2], dtype=float)
        for goal in creature.get("goals", []):
            point = np.asarray(goal["position"][:2], dtype=float)
            away = float(np.linalg.norm(point - start))
            if away > metres:
                goal["position"][:2] = (start + (point - start) * (metres / away)).tolist()
    return scene


def run(
    creatures: int,
    seconds: float,
    lod: bool,
    every: int,
    seed: int,
    within: float | None,
    nudge: float = 0.0,
    model: dict[str, float] | None = None,
    reduced: int | None = None,
) -> dict[str, Any]:
    """One run (every start moved `nudge` metres along x; its reduced creatures on
    `model`, `reduced_models.model_settings`; with `reduced`, the scene's reduced budget,
    `physics.lod.reduced`); its figures."""
    use_model(model)
    scene = crowd_scene(creatures, seed=seed)
    if reduced is not None:
        scene.setdefault("physics", {}).setdefault("lod", {})["reduced"] = reduced
    if within is not None:
        scene = goals_within(scene, within)
    for creature in scene["creatures"]:
        creature["position"][0] += nudge
    goals = {
        c["name"]: np.asarray(c["goals"][0]["position"][:2], float) for c in scene["creatures"]
    }
    reached: dict[str, float] = {}
    deepest = 0.0
    start = time.perf_counter()
    with World.from_scene(scene, lod=lod) as world:
        names = {e: c.name for e, c in world.query(Creature)}

        def arrived(**event: Any) -> None:
            reached.setdefault(names[event["creature"]], world.time)

        world.events.on("goal_reached", arrived)
        first = {n: world.component(e, Transform).pos[:2].copy() for e, n in names.items()}
        rows, half, radius = _capsules(world)
        frames = round(seconds * world.settings.fps)
        for frame in range(frames):
            world.step()
            if frame % every == 0:
                deepest = max(deepest, deepest_overlap(world, rows, half, radius))
        last = {n: world.component(e, Transform).pos[:2].copy() for e, n in names.items()}
        progress = {
            n: float(np.linalg.norm(goals[n] - first[n]) - np.linalg.norm(goals[n] - last[n]))
            for n in names.values()
        }
        return {
            "lod": lod,
            "progress": progress,
            "reached": reached,
            "deepest_mm": 1000.0 * deepest,
            "recoveries": world.physics.health.recoveries,
            "tiers": world.lod.counts(),
            "promotions": world.lod.promotions,
            "wall_s": time.perf_counter() - start,
        }


def compare(on: dict[str, Any], off: dict[str, Any]) -> dict[str, Any]:
    """The figures the two runs are judged by."""
    mean_on = float(np.mean(list(on["progress"].values())))
    mean_off = float(np.mean(list(off["progress"].values())))
    both = sorted(set(on["reached"]) & set(off["reached"]))
    apart = [abs(on["reached"][n] - off["reached"][n]) for n in both]
    return {
        "mean_progress_m": {"lod": mean_on, "off": mean_off},
        "progress_ratio": mean_on / mean_off if mean_off else float("nan"),
        "reached": {"lod": len(on["reached"]), "off": len(off["reached"]), "both": len(both)},
        "only_one_run_reached": sorted(set(on["reached"]) ^ set(off["reached"])),
        "arrival_apart_s_max": max(apart, default=0.0),
        "arrival_apart_s_median": float(np.median(apart)) if apart else 0.0,
        "arrivals_within_2s": sum(a <= 2.0 for a in apart),
        "arrival_apart_s": {n: a for n, a in zip(both, apart, strict=True) if a > 2.0},
        "deepest_mm": {"lod": on["deepest_mm"], "off": off["deepest_mm"]},
        "recoveries": {"lod": on["recoveries"], "off": off["recoveries"]},
        "tiers_at_end": on["tiers"],
        "promotions": on["promotions"],
        "wall_s": {"lod": on["wall_s"], "off": off["wall_s"]},
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--creatures", type=int, default=64)
    parser.add_argument("--seconds", type=float, default=20.0)
    parser.add_argument("--every", type=int, default=5, help="frames between overlap samples")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument(
        "--goals-within",
        type=float,
        default=None,
        metavar="M",
        help="bring every goal to at most M metres from its start (arrivals within the run)",
    )
    parser.add_argument(
        "--nudge",
        type=float,
        default=None,
        metavar="M",
        help="compare lod off with lod off, every start moved M metres: how far apart two"
        " full runs drift on their own (the floor of the comparison)",
    )
    parser.add_argument(
        "--model", help="KEY=VALUE,...: another reduced model (links, rate, gain, damping)"
    )
    parser.add_argument(
        "--reduced",
        type=int,
        default=None,
        metavar="N",
        help="the level of detail's reduced budget (physics.lod.reduced; default the"
        " scene's, 128): what a smaller or larger budget costs in fidelity",
    )
    parser.add_argument("--json", action="store_true", help="one JSON object")
    args = parser.parse_args(argv)
    if args.reduced is not None and args.reduced < 0:
        parser.error(f"--reduced: must be >= 0 creatures, got {args.reduced}")
    if args.creatures < 1 or args.seconds <= 0 or args.every < 1:
        parser.error("--creatures and --every must be >= 1, --seconds > 0")
    if args.goals_within is not None and not args.goals_within > 0:
        parser.error(f"--goals-within: must be > 0 metres, got {args.goals_within}")
    if args.nudge is not None and not (math.isfinite(args.nudge) and args.nudge != 0.0):
        parser.error(f"--nudge: must be a distance other than 0, got {args.nudge}")
    try:
        model = None if args.model is None else model_settings(args.model)
    except ValueError as error:
        parser.error(f"--model: {error}")
    first = (True, 0.0) if args.nudge is None else (False, args.nudge)
    with ProcessPoolExecutor(2) as pool:
        common = (args.creatures, args.seconds)
        extra = (args.every, args.seed, args.goals_within)
        runs = [
            pool.submit(run, *common, lod, *extra, nudge, model, args.reduced)
            for lod, nudge in (first, (False, 0.0))
        ]
        on, off = (r.result() for r in runs)
    result = {
        "creatures": args.creatures,
        "seconds": args.seconds,
        "goals_within_m": args.goals_within,
        "nudge_m": args.nudge,
        "model": model,
        "reduced_budget": args.reduced,
        **compare(on, off),
    }
    if args.json:
        print(json.dumps(result))
        return 0
    progress = result["mean_progress_m"]
    if args.nudge is None:
        print(
            f"{args.creatures} creatures, {args.seconds:g} s, lod on (tiers at the end"
            f" {result['tiers_at_end']}, {result['promotions']} promotions) against lod off"
        )
    else:
        print(
            f"{args.creatures} creatures, {args.seconds:g} s, lod off with every start moved"
            f" {args.nudge:g} m against lod off (the 'lod' figures are the moved run's)"
        )
    print(
        f"  mean progress toward goals: {progress['lod']:.3f} m against {progress['off']:.3f} m "
        f"(ratio {result['progress_ratio']:.3f})"
    )
    reached = result["reached"]
    if reached["lod"] == reached["off"] == 0:
        print(
            "  goals reached: none in either run, so no arrival times to compare (the goals"
            " are farther than the run's crawling: --goals-within M brings them nearer)"
        )
    else:
        print(
            f"  goals reached: {reached['lod']} against {reached['off']} ({reached['both']} in"
            f" both; arrival times a median {result['arrival_apart_s_median']:.2f} s and at"
            f" most {result['arrival_apart_s_max']:.2f} s apart, {result['arrivals_within_2s']}"
            f" within 2 s; only in one run: {', '.join(result['only_one_run_reached']) or 'none'})"
        )
    late = result["arrival_apart_s"]
    if late:
        print("  more than 2 s apart: " + ", ".join(f"{n} {a:.1f} s" for n, a in late.items()))
    deepest = result["deepest_mm"]
    print(f"  deepest interpenetration: {deepest['lod']:.1f} mm against {deepest['off']:.1f} mm")
    recoveries = result["recoveries"]
    print(
        f"  recoveries: {recoveries['lod']} against {recoveries['off']}; wall "
        f"{result['wall_s']['lod']:.0f} s against {result['wall_s']['off']:.0f} s"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
