"""Locomotion report: does every creature reach its goal, how fast, how cleanly?

    python tools/locomotion_report.py                 # the full table (runs on 2 processes)
    python tools/locomotion_report.py --json          # one JSON row per case
    python tools/locomotion_report.py --only 4 --gait coordinated

Cases: creatures with 3, 4, 5, 6 and 8 tentacles, a goal 10 mantle radii away in
front (+x, along tentacle 0), behind and to the side, in both gaits; the bundled
`three_goals.json` (all goals, in order); idle (no goal, 30 s: drift and joint motion).
Every case runs headless for at most 60 simulated seconds.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
from concurrent.futures import ProcessPoolExecutor
from typing import Any

import numpy as np

from ecs_tentacles.components import Creature, Transform
from ecs_tentacles.locomotion.goals import GoalBook
from ecs_tentacles.locomotion.params import Locomotion
from ecs_tentacles.locomotion.stores import LocomotionStores
from ecs_tentacles.numeric.quaternions import quat_rotate
from ecs_tentacles.scene.load import bundled_scene
from ecs_tentacles.scene.parameters import parameter
from ecs_tentacles.world import World

TENTACLE_COUNTS = (3, 4, 5, 6, 8)
DIRECTIONS = {"front": 0.0, "side": 90.0, "behind": 180.0}
GAITS = parameter("locomotion", "gait").choices
LIMIT_SECONDS = 60.0
IDLE_SECONDS = 30.0
MANTLE_RADIUS = 0.15


def case_scene(tentacles: int, gait: str, direction_deg: float | None) -> dict[str, Any]:
    """One creature at the origin, and a goal 10 mantle radii away (or none)."""
    creature: dict[str, Any] = {
        "name": "crawler",
        "mantle": {"radius": MANTLE_RADIUS},
        "tentacles": {"count": tentacles},
        "locomotion": {"gait": gait},
    }
    if direction_deg is not None:
        angle = np.radians(direction_deg)
        distance = 10 * MANTLE_RADIUS
        creature["goals"] = [{"position": [distance * np.cos(angle), distance * np.sin(angle)]}]
    return {"version": 1, "seed": tentacles, "creatures": [creature]}


def run(world: World, case: str, seconds: float) -> dict[str, Any]:
    """Step until every goal is reached or `seconds` pass; measure the run."""
    entity = world.creature(next(c.name for _, c in world.query(Creature)))
    mantle = world.component(entity, Transform)
    reached: list[float] = []
    world.events.on("goal_reached", lambda **kw: reached.append(world.time))
    goals_at_start = len(world.resource(GoalBook).path(entity))
    start = mantle.pos[:2].copy()
    previous = start.copy()
    travelled = 0.0
    deepest = 0.0
    flipped = False
    angles = []
    data = world.physics.views[0].data
    while world.time < seconds - 1e-9:
        world.step(1)
        here = mantle.pos[:2]
        travelled += float(np.linalg.norm(here - previous))
        previous = here.copy()
        deepest = max(deepest, -data.deepest_contact)
        flipped |= bool(quat_rotate(mantle.quat, np.array([0.0, 0.0, 1.0]))[2] < 0.0)
        if world.frame % 6 == 0:
            angles.append(data.qpos[7:].copy())
        if goals_at_start and len(reached) == goals_at_start:
            break
    finite = bool(np.isfinite(data.qpos).all() and np.isfinite(data.qvel).all())
    creature = world.component(entity, Creature)
    t = world.tentacles
    left_behind = 0
    s = world.suckers
    for row in np.flatnonzero(s.attached):
        tentacle = s.tentacle_row[row]
        base = world.transforms.pos[t.base_row[tentacle], :2]
        distance = np.linalg.norm(base - s.anchor[row, :2])
        left_behind += int(
            distance
            > world.resource(LocomotionStores).creatures.release_reach[0] * t.length[tentacle]
        )
    elapsed = world.time
    displacement = float(np.linalg.norm(mantle.pos[:2] - start))
    return {
        "case": case,
        "tentacles": len(creature.tentacles),
        "gait": world.resource(Locomotion).get(entity)["gait"],
        "reached": bool(goals_at_start) and len(reached) == goals_at_start,
        "time_s": round(elapsed, 3),
        "speed_radii_per_s": round(displacement / MANTLE_RADIUS / elapsed, 4),
        "path_efficiency": round(displacement / travelled, 4) if travelled > 0 else None,
        "attaches": int(world.events.counts["sucker_attached"]),
        "max_penetration_m": round(deepest, 5),
        "finite": finite,
        "flipped": flipped,
        "suckers_left_behind": left_behind,
        "drift_radii": round(displacement / MANTLE_RADIUS, 4),
        "joint_std_rad": round(float(np.std(np.array(angles), axis=0).mean()), 4)
        if angles
        else 0.0,
        "goal_times_s": [round(x, 3) for x in reached],
    }


def run_case(spec: tuple[str, int, str, float | None]) -> dict[str, Any]:
    """Build and run one case of the table."""
    case, tentacles, gait, direction = spec
    if case == "three_goals":
        world = World.from_scene(bundled_scene("three_goals"))
        world.resource(Locomotion).set(world.creature("crawler"), gait=gait)
        row = run(world, case, LIMIT_SECONDS)
    else:
        world = World.from_scene(case_scene(tentacles, gait, direction))
        row = run(world, case, IDLE_SECONDS if direction is None else LIMIT_SECONDS)
    world.close()
    return row


def cases(only: int | None, gait: str | None) -> list[tuple[str, int, str, float | None]]:
    gaits = [gait] if gait else list(GAITS)
    specs: list[tuple[str, int, str, float | None]] = []
    for n in [only] if only else TENTACLE_COUNTS:
        for g in gaits:
            for name, angle in DIRECTIONS.items():
                specs.append((f"{n}_{name}", n, g, angle))
    if only is None:
        specs += [("three_goals", 6, g, 0.0) for g in gaits]
        specs += [("idle", 8, gaits[0], None)]
    return specs


def summary(rows: list[dict[str, Any]]) -> list[str]:
    """Lines comparing the gaits on the goal cases."""
    goal_rows = [r for r in rows if r["case"] not in ("idle",)]
    lines = []
    by_gait = {g: [r for r in goal_rows if r["gait"] == g] for g in GAITS}
    if all(by_gait.values()):
        med = {g: statistics.median(r["time_s"] for r in by_gait[g]) for g in GAITS}
        lines.append(
            f"median time to goal: cyclic {med['cyclic']:.1f} s,"
            f" coordinated {med['coordinated']:.1f} s"
            f" -> coordinated is {med['cyclic'] / med['coordinated']:.2f}x as fast"
        )
    missed = [f"{r['case']}/{r['gait']}" for r in goal_rows if not r["reached"]]
    lines.append(
        f"reached: {len(goal_rows) - len(missed)}/{len(goal_rows)}"
        + (f" (missed {missed})" if missed else "")
    )
    bad = [r["case"] for r in rows if not r["finite"] or r["flipped"] or r["suckers_left_behind"]]
    lines.append(f"NaN, flipped or sucker left behind: {bad or 'none'}")
    return lines


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", action="store_true", help="print a JSON list, one row per case")
    parser.add_argument("--only", type=int, choices=TENTACLE_COUNTS, help="one tentacle count")
    parser.add_argument("--gait", choices=GAITS, help="one gait")
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    specs = cases(args.only, args.gait)
    with ProcessPoolExecutor(max_workers=args.workers) as pool:
        rows = []
        for row in pool.map(run_case, specs):
            rows.append(row)
            print(f"  {row['case']:<12} {row['gait']:<11} done", file=sys.stderr)
    if args.json:
        print(json.dumps(rows, indent=1))
        return
    print(
        f"{'case':<12} {'n':>2} {'gait':<11} {'reached':<7} {'time_s':>6} {'radii/s':>7}"
        f" {'effic':>5} {'attach':>6} {'pen_mm':>6}"
    )
    for r in rows:
        print(
            f"{r['case']:<12} {r['tentacles']:>2} {r['gait']:<11} {r['reached']!s:<7}"
            f" {r['time_s']:>6.1f} {r['speed_radii_per_s']:>7.3f}"
            f" {r['path_efficiency'] or 0:>5.2f} {r['attaches']:>6}"
            f" {1000 * r['max_penetration_m']:>6.1f}"
            + (
                f"  drift {r['drift_radii']:.2f} radii, joint std {r['joint_std_rad']:.3f} rad"
                if r["case"] == "idle"
                else ""
            )
        )
    for line in summary(rows):
        print(line)


if __name__ == "__main__":
    main()
