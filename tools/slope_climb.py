"""Slope climbing: how steep a ramp the bundled octopus crawls up to a goal.

    python tools/slope_climb.py                      # 0 to 35 degrees in 5s, 90 s each
    python tools/slope_climb.py --slopes 0,15,30 --seconds 60 --out build/slopes

For each slope the octopus (`assets/scenes/octopus.json`'s creature) starts on the flat,
its mantle `START` m before the foot of a heightfield ramp, with a goal `UP` m up the
ramp (measured along the slope). Each slope runs in its own process (one per core).
Writes `<out>.csv` (slope, reached, seconds to the goal or empty, metres climbed along
the slope, recoveries) and `<out>.png` (metres climbed and seconds to the goal against
the slope), and prints the steepest slope whose goal was reached. Progress on stderr.
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import multiprocessing
import os
import sys
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.figure import Figure

from ecs_tentacles.output.atomic import atomic_output

START = 0.9  # metres from the mantle to the foot of the ramp
UP = 2.0  # metres along the slope from the foot to the goal
FLAT = 4.0  # metres of flat ground before the foot
SLOPES = (0, 5, 10, 15, 20, 25, 30, 35)
COLUMNS = ("slope_deg", "reached", "seconds", "climbed_m", "recoveries")


def ramp_scene(slope_deg: float) -> dict[str, Any]:
    """The octopus on the flat before a heightfield ramp of `slope_deg`, goal up it."""
    from ecs_tentacles.scene.load import bundled_scene

    octopus = json.loads(bundled_scene("octopus").read_text(encoding="utf-8"))["creatures"][0]
    rise = math.tan(math.radians(slope_deg))
    run = UP * math.cos(math.radians(slope_deg)) + 2.0  # the ramp goes on past the goal
    size_x = FLAT + run
    xs = np.linspace(-0.5 * size_x, 0.5 * size_x, round(size_x / 0.1) + 1)
    foot = -0.5 * size_x + FLAT
    row = [round(rise * max(0.0, x - foot), 5) for x in xs]
    creature = {k: v for k, v in octopus.items() if k != "goals"}
    creature["position"] = [foot - START, 0.0]
    goal_x = foot + UP * math.cos(math.radians(slope_deg))
    creature["goals"] = [{"position": [round(goal_x, 4), 0.0]}]
    return {
        "version": 1,
        "name": f"slope_{slope_deg:g}",
        "seed": 1,
        "terrain": {"heightfield": {"size": [round(size_x, 3), 4.0], "heights": [row] * 21}},
        "creatures": [creature],
    }


def climb(slope_deg: float, seconds: float) -> dict[str, Any]:
    """Run one slope; what it reached."""
    from ecs_tentacles.world import World

    world = World.from_scene(ramp_scene(slope_deg))
    try:
        reached: list[float] = []
        world.events.on("goal_reached", lambda **_: reached.append(world.time))
        foot = world.scene["creatures"][0]["position"][0] + START  # type: ignore[index]
        best = 0.0
        while world.time < seconds and not reached:
            world.step()
            x = float(world.transforms.pos[world.creatures.mantle_row[0], 0])
            best = max(best, (x - foot) / math.cos(math.radians(slope_deg)))
        return {
            "slope_deg": slope_deg,
            "reached": bool(reached),
            "seconds": round(reached[0], 2) if reached else "",
            "climbed_m": round(UP if reached else max(0.0, best), 3),
            "recoveries": world.physics.health.recoveries,
        }
    finally:
        world.close()


def write_csv(rows: list[dict[str, Any]], path: Path) -> None:
    with atomic_output(path) as temporary, open(temporary, "w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=COLUMNS)
        writer.writeheader()
        writer.writerows(rows)


def plot(rows: list[dict[str, Any]], path: Path, seconds: float) -> None:
    slopes = [r["slope_deg"] for r in rows]
    figure = Figure(figsize=(8, 3.6), layout="constrained")
    left, right = figure.subplots(1, 2)
    left.plot(slopes, [r["climbed_m"] for r in rows], "o-", color="tab:blue")
    left.axhline(UP, color="grey", lw=0.8, ls="--")
    left.set(
        xlabel="slope (degrees)", ylabel="metres up the slope", title=f"climbed in {seconds:g} s"
    )
    done = [(r["slope_deg"], r["seconds"]) for r in rows if r["reached"]]
    if done:
        right.plot(*zip(*done, strict=True), "o-", color="tab:orange")
    right.set(xlabel="slope (degrees)", ylabel="seconds", title=f"time to a goal {UP:g} m up")
    with atomic_output(path) as temporary:
        figure.savefig(temporary, format="png", dpi=110)


def _said(row: dict[str, Any]) -> dict[str, Any]:
    got = f"reached in {row['seconds']} s" if row["reached"] else f"{row['climbed_m']} m up"
    print(f"slope {row['slope_deg']:g} deg: {got}", file=sys.stderr)
    return row


def number_list(text: str) -> list[float]:
    try:
        values = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"not a comma-separated list of numbers: {text!r}"
        ) from None
    if not values or not all(0.0 <= v <= 60.0 for v in values):
        raise argparse.ArgumentTypeError("slopes must be degrees in [0, 60]")
    return values


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "--slopes", type=number_list, default=list(SLOPES), help="degrees, e.g. 0,10,20"
    )
    parser.add_argument(
        "--seconds", type=float, default=90.0, help="simulated seconds per slope (default 90)"
    )
    parser.add_argument(
        "--out", type=Path, default=Path("slope_climb"), help="output prefix (default slope_climb)"
    )
    parser.add_argument(
        "--jobs", type=int, default=os.cpu_count() or 1, help="slopes run at once (default: cores)"
    )
    args = parser.parse_args(argv)
    if args.jobs < 1:
        parser.error("--jobs: must be >= 1")
    if not 1.0 <= args.seconds <= 3600.0:
        parser.error("--seconds: must be in [1, 3600]")
    rows = []
    if args.jobs == 1:
        results = (climb(s, args.seconds) for s in args.slopes)
        for row in results:
            rows.append(_said(row))
    else:  # fresh interpreters: forking a process that runs threads can deadlock
        context = multiprocessing.get_context("spawn")
        with ProcessPoolExecutor(max_workers=args.jobs, mp_context=context) as pool:
            futures = [pool.submit(climb, s, args.seconds) for s in args.slopes]
            for future in as_completed(futures):
                rows.append(_said(future.result()))
    rows.sort(key=lambda r: r["slope_deg"])
    args.out.parent.mkdir(parents=True, exist_ok=True)
    write_csv(rows, args.out.with_suffix(".csv"))
    plot(rows, args.out.with_suffix(".png"), args.seconds)
    steepest = max((r["slope_deg"] for r in rows if r["reached"]), default=None)
    print(f"steepest slope climbed to the goal: {steepest if steepest is not None else 'none'} deg")
    print(f"wrote {args.out.with_suffix('.csv')} and {args.out.with_suffix('.png')}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
