"""The reduced tier's pace, creature by creature: each creature's progress toward its goal
with every creature reduced over its progress with every creature full.

    python tools/reduced_pace.py                       # 32 creatures, 10 s, seeds 0-3
    python tools/reduced_pace.py --seeds 0 --seconds 5 --json
    python tools/reduced_pace.py --servos 25/0.5,25/5,100/0.5   # servo settings instead
    python tools/reduced_pace.py --model links=1,rate=1,gain=1,damping=1   # an ablation

Runs `crowd_scene(N, seed)` (eight body plans, varied behaviour) with the grid spread
wide (`--spacing`, 8 m: nobody meets anybody, so contact and avoidance play no part)
twice per seed, in two processes: level of detail on with budgets full 0 and reduced
N (everyone reduced), and lod off (everyone full). Reports, over all seeds' creatures:
the ratio of the summed progress (1.0: the reduced crowd crawls as far), the spread of
the per-creature ratios (sd, range: what makes one creature arrive late while the
crowd's mean looks right), their correlation with the mantle radius (a heavy creature
whose reduced tentacles sag more than its full ones shows here) and the ratio for the
big and the small mantles. The floor: two full runs with every start moved 1 cm give
per-creature ratios with an sd of about 0.01.

With `--servos STRENGTH/DAMPING,...` the crowds are of the default octopus instead
(`--uniform`: one body plan, behaviour still varied), every tentacle's servos set to
each given strength and damping in turn, and the progress ratio is reported per
setting: how the reduced tier's pace holds up across the servo sliders.

With `--model KEY=VALUE,...` the reduced runs take another reduced model
(`tools/reduced_models.py`: links, rate, gain, damping), to see which of its
simplifications makes which part of the spread. Every run also reports each body plan's
ratio and how its creatures spread about it (what a pace correction per body plan could
and could not take away).
"""

from __future__ import annotations

import argparse
import json
from concurrent.futures import ProcessPoolExecutor
from typing import Any

import numpy as np
from reduced_models import DEFAULT_MODEL, model_settings, use_model

from ecs_tentacles.creator.crowd import crowd_scene
from ecs_tentacles.locomotion.stores import LocomotionStores
from ecs_tentacles.world import World

BIG_MANTLE = 0.16  # m: the body plans' mantle radii run about 0.11-0.19


def run(
    creatures: int,
    seconds: float,
    seed: int,
    spacing: float,
    reduced: bool,
    servo: tuple[float, float] | None = None,
    model: dict[str, float] | None = None,
) -> dict[str, Any]:
    """One crowd, everyone reduced or everyone full: each creature's progress (m) toward
    its goal in `seconds`, its mantle radius, the tiers at the end. With `servo`
    (strength, damping): default octopuses, every servo set to it; with `model`
    (`model_settings`): that reduced model."""
    use_model(model)
    scene = crowd_scene(creatures, seed=seed, spacing=spacing, uniform=servo is not None)
    if servo is not None:
        for creature in scene["creatures"]:
            tentacles = creature.setdefault("tentacles", {})
            tentacles["strength"], tentacles["damping"] = servo
            for override in tentacles.get("overrides", []):
                override.pop("strength", None)
                override.pop("damping", None)
    if reduced:
        scene.setdefault("physics", {})["lod"] = {"full": 0, "reduced": creatures}
    with World.from_scene(scene, threads=1, lod=reduced) as world:
        gaits = world.resource(LocomotionStores).creatures
        mantle = world.creatures.mantle_row
        goal = gaits.goal[:, :2].copy()
        start = world.transforms.pos[mantle, :2].copy()
        world.step(round(seconds * world.settings.fps))
        end = world.transforms.pos[mantle, :2]
        progress = np.linalg.norm(goal - start, axis=1) - np.linalg.norm(goal - end, axis=1)
        plan = np.zeros(len(progress), dtype=np.int64)  # body plan: one batch, one model
        for batch in world.physics.batches:
            plan[batch.members] = batch.index
        return {
            "progress": progress.tolist(),
            "plan": plan.tolist(),
            "mantle_radius": world.creatures.mantle_radius.tolist(),
            "tiers": world.lod.counts(),
        }


def summary(pairs: list[tuple[dict[str, Any], dict[str, Any]]]) -> dict[str, Any]:
    """The figures of (reduced, full) runs of the same crowds (module docstring)."""
    reduced = np.concatenate([r["progress"] for r, _ in pairs])
    full = np.concatenate([f["progress"] for _, f in pairs])
    radius = np.concatenate([f["mantle_radius"] for _, f in pairs])
    ratio = reduced / np.maximum(full, 1e-9)
    big = radius >= BIG_MANTLE
    # per body plan (crowd by crowd): its summed ratio, and its creatures' spread about it
    plan_ratios, within = [], []
    for crowd, (r, f) in enumerate(pairs):
        plans, mine = np.asarray(f["plan"]), ratio[crowd_slice(pairs, crowd)]
        for plan in np.unique(plans):
            at = plans == plan
            plan_ratios.append(
                np.sum(np.asarray(r["progress"])[at]) / np.sum(np.asarray(f["progress"])[at])
            )
            within.append(mine[at] - plan_ratios[-1])
    return {
        "creatures": len(ratio),
        "progress_ratio": float(reduced.sum() / full.sum()),
        "ratio_sd": float(ratio.std()),
        "ratio_min": float(ratio.min()),
        "ratio_max": float(ratio.max()),
        "mantle_correlation": float(np.corrcoef(radius, ratio)[0, 1])
        if ratio.std() and radius.std()
        else 0.0,
        "big_mantle_ratio": float(reduced[big].sum() / full[big].sum()) if big.any() else None,
        "small_mantle_ratio": float(reduced[~big].sum() / full[~big].sum())
        if (~big).any()
        else None,
        "plans": len(plan_ratios),
        "plan_ratio_min": float(min(plan_ratios)),
        "plan_ratio_max": float(max(plan_ratios)),
        "plan_ratio_sd": float(np.std(plan_ratios)),
        "within_plan_sd": float(np.concatenate(within).std()),
        "tiers_reduced_run": [r["tiers"] for r, _ in pairs],
    }


def crowd_slice(pairs: list[tuple[dict[str, Any], dict[str, Any]]], crowd: int) -> slice:
    """Where crowd `crowd`'s creatures are in the per-creature arrays of all `pairs`."""
    start = sum(len(f["progress"]) for _, f in pairs[:crowd])
    return slice(start, start + len(pairs[crowd][1]["progress"]))


def servo_list(text: str) -> list[tuple[float, float]]:
    """ "25/0.5,100/2" -> [(25.0, 0.5), (100.0, 2.0)]; ValueError naming a bad item."""
    out = []
    for item in text.split(","):
        parts = item.split("/")
        try:
            strength, damping = (float(p) for p in parts)
        except ValueError:
            raise ValueError(f"STRENGTH/DAMPING pairs separated by commas, got {item!r}") from None
        out.append((strength, damping))
    return out


def servo_sweep(
    servos: list[tuple[float, float]],
    creatures: int,
    seconds: float,
    seeds: list[int],
    spacing: float,
    model: dict[str, float] | None = None,
) -> list[dict[str, Any]]:
    """Per servo setting: `summary` of its crowds run reduced (with `model`) and full, with
    the setting."""
    out = []
    with ProcessPoolExecutor(2) as pool:
        for servo in servos:
            pairs = []
            for seed in seeds:
                common = (creatures, seconds, seed, spacing)
                reduced, full = (
                    pool.submit(run, *common, tier, servo, model) for tier in (True, False)
                )
                pairs.append((reduced.result(), full.result()))
            strength, damping = servo
            out.append({"strength": strength, "damping": damping, **summary(pairs)})
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--creatures", type=int, default=32, help="creatures per crowd")
    parser.add_argument("--seconds", type=float, default=10.0, help="simulated seconds")
    parser.add_argument("--seeds", default="0,1,2,3", help="crowd seeds, comma separated")
    parser.add_argument("--spacing", type=float, default=8.0, help="grid spacing (m)")
    parser.add_argument(
        "--servos", help="STRENGTH/DAMPING,...: default octopuses at each servo setting"
    )
    parser.add_argument(
        "--model", help="KEY=VALUE,...: another reduced model (links, rate, gain, damping)"
    )
    parser.add_argument("--json", action="store_true", help="one JSON object")
    args = parser.parse_args()
    if args.creatures < 2 or not args.seconds > 0 or not args.spacing > 0:
        parser.error("--creatures must be >= 2, --seconds and --spacing > 0")
    try:
        seeds = [int(s) for s in args.seeds.split(",")]
    except ValueError:
        parser.error(f"--seeds: comma-separated integers, got {args.seeds!r}")
    model = None
    if args.model is not None:
        try:
            model = model_settings(args.model)
        except ValueError as error:
            parser.error(f"--model: {error}")
        if not args.json:
            chosen = {**DEFAULT_MODEL, **model}
            print("reduced model: " + ", ".join(f"{k} {v:g}" for k, v in chosen.items()))
    if args.servos is not None:
        try:
            servos = servo_list(args.servos)
        except ValueError as error:
            parser.error(f"--servos: {error}")
        by_servo = servo_sweep(servos, args.creatures, args.seconds, seeds, args.spacing, model)
        if args.json:
            print(json.dumps(by_servo))
            return
        print(f"default octopuses, {len(seeds)} crowds of {args.creatures}, {args.seconds:g} s,")
        print("all reduced against all full, progress ratio per servo setting:")
        for row in by_servo:
            print(
                f"  strength {row['strength']:g} / damping {row['damping']:g}:"
                f" {row['progress_ratio']:.3f} (sd {row['ratio_sd']:.3f})"
            )
        return
    pairs = []
    with ProcessPoolExecutor(2) as pool:
        for seed in seeds:
            common = (args.creatures, args.seconds, seed, args.spacing)
            reduced, full = (pool.submit(run, *common, tier, None, model) for tier in (True, False))
            pairs.append((reduced.result(), full.result()))
    result = summary(pairs)
    if args.json:
        print(json.dumps(result))
        return
    print(
        f"{result['creatures']} creatures ({len(seeds)} crowds), {args.seconds:g} s, "
        f"all reduced against all full\n"
        f"  progress: {result['progress_ratio']:.3f} of full; per creature sd "
        f"{result['ratio_sd']:.3f}, {result['ratio_min']:.2f}-{result['ratio_max']:.2f}\n"
        f"  correlation with the mantle radius {result['mantle_correlation']:+.2f}; mantles "
        f">= {BIG_MANTLE} m {result['big_mantle_ratio']:.3f}, smaller "
        f"{result['small_mantle_ratio']:.3f}\n"
        f"  by body plan ({result['plans']}): {result['plan_ratio_min']:.2f}-"
        f"{result['plan_ratio_max']:.2f} of full, sd {result['plan_ratio_sd']:.3f}; creatures"
        f" about their plan's ratio, sd {result['within_plan_sd']:.3f}"
    )


if __name__ == "__main__":
    main()
