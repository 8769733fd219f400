"""The framework's overhead over MuJoCo alone, lod off: the median of interleaved runs.

    python tools/overhead.py               # 16, 64, 256 creatures; 1 and 2 threads; 3 runs
    python tools/overhead.py --sizes 16 --threads 2 --repeat 5 --json

Each run is `ecs-tentacles bench --crowd N --uniform --lod off --threads T` in a fresh
process (`crowd_scaling.bench_once`); its `overhead_ratio` is a framework frame over
MuJoCo alone stepping the very same inputs (`ecs_tentacles.physics.bare`). The runs
are interleaved (every size and thread count once, then again), so a slow spell of a
shared machine falls on all of them alike, and each setting's median is reported with
its runs. Exit code 1 when a run failed, else 0. Progress goes to stderr.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))
from crowd_scaling import WARMUP, bench_once, number_list

TARGET = 1.10  # the design's bound on the overhead (DESIGN.md, performance rules)


def measure(
    sizes: list[int], threads: list[int], repeat: int, frames: int, warmup: int, timeout: float
) -> list[dict[str, Any]]:
    """Per (creatures, threads): every run's overhead ratio and their median."""
    runs: dict[tuple[int, int], list[float]] = {(n, t): [] for n in sizes for t in threads}
    errors: dict[tuple[int, int], str] = {}
    extra = ("--uniform", "--warmup", str(warmup))
    for index in range(repeat):
        for (creatures, count), ratios in runs.items():
            print(
                f"run {index + 1}/{repeat}: {creatures} creatures, {count} threads", file=sys.stderr
            )
            row = bench_once(creatures, count, frames, 0, timeout, extra, "off")
            if row["error"]:
                errors[(creatures, count)] = row["error"]
                print(f"    failed: {row['error']}", file=sys.stderr)
            else:
                ratios.append(float(row["overhead_ratio"]))
    return [
        {
            "creatures": creatures,
            "threads": count,
            "overhead_ratios": ratios,
            "median": statistics.median(ratios) if ratios else None,
            "within_target": bool(ratios) and statistics.median(ratios) <= TARGET,
            "error": errors.get((creatures, count), ""),
        }
        for (creatures, count), ratios in runs.items()
    ]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--sizes", type=number_list, default=[16, 64, 256], help="creatures")
    parser.add_argument("--threads", type=number_list, default=[1, 2], help="thread counts")
    parser.add_argument("--repeat", type=int, default=3, help="runs of each setting (default 3)")
    parser.add_argument("--frames", type=int, default=40, help="timed frames per run")
    parser.add_argument("--warmup", type=int, default=WARMUP, help="untimed frames first")
    parser.add_argument("--timeout", type=float, default=3600.0, help="seconds allowed per run")
    parser.add_argument("--json", action="store_true", help="one JSON list")
    args = parser.parse_args(argv)
    if args.repeat < 1 or args.frames < 1 or args.warmup < 0:
        parser.error("--repeat and --frames must be >= 1, --warmup >= 0")
    results = measure(args.sizes, args.threads, args.repeat, args.frames, args.warmup, args.timeout)
    if args.json:
        print(json.dumps(results))
    else:
        for r in results:
            runs = ", ".join(f"{x:.3f}" for x in r["overhead_ratios"])
            median = "failed" if r["median"] is None else f"{r['median']:.3f}"
            mark = "" if r["within_target"] else f"  (over {TARGET})"
            print(f"{r['creatures']:>6} creatures, {r['threads']} threads: {median} ({runs}){mark}")
    return 1 if any(r["error"] for r in results) else 0


if __name__ == "__main__":
    raise SystemExit(main())
