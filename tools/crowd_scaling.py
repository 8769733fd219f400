"""Crowd scaling: build seconds and frame cost per creature, 1 to 1,024 creatures.

    python tools/crowd_scaling.py                          # 1 4 16 64 256 1024, 1 and all threads
    python tools/crowd_scaling.py --sizes 1,4,16 --frames 60 --out build/scaling

Each (creatures, threads) pair runs `ecs-tentacles bench --crowd N --threads T --json`
in a fresh process, so one size's memory and compiled models never weigh on the
next. Writes `<out>.csv` (one row per run; a failed run keeps its error and leaves
the numbers empty) and `<out>.png`: build seconds and frame ms per creature against
creatures (log x), one line per thread count. Progress goes to stderr.
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import subprocess
import sys
from pathlib import Path
from typing import Any

from matplotlib.figure import Figure
from matplotlib.ticker import FuncFormatter, NullFormatter

from ecs_tentacles.atomic import atomic_output

SIZES = (1, 4, 16, 64, 256, 1024)
BENCH_KEYS = (
    "compiles",
    "bodies",
    "build_s",
    "frame_ms",
    "physics_ms",
    "raw_mujoco_ms",
    "overhead_ratio",
    "realtime_factor",
    "rss_mb",
)
COLUMNS = (
    "creatures",
    "threads",
    *BENCH_KEYS[:3],
    "build_s_per_creature",
    "frame_ms",
    "frame_ms_per_creature",
    *BENCH_KEYS[4:],
    "error",
)


def bench_once(
    creatures: int,
    threads: int,
    frames: int,
    seed: int,
    timeout: float,
    extra: tuple[str, ...] = (),
) -> dict[str, Any]:
    """One CSV row: `ecs-tentacles bench --crowd` (+ `extra` options) in a fresh process."""
    command = [sys.executable, "-m", "ecs_tentacles.cli", "bench", "--crowd", str(creatures)]
    command += ["--threads", str(threads), "--frames", str(frames), "--seed", str(seed), "--json"]
    command += extra
    row: dict[str, Any] = {"creatures": creatures, "threads": threads, "error": ""}
    try:
        done = subprocess.run(command, capture_output=True, text=True, timeout=timeout, check=False)
    except subprocess.TimeoutExpired:
        row["error"] = f"timed out after {timeout:g} s"
        return row
    if done.returncode != 0:
        lines = done.stderr.strip().splitlines() or [f"exit code {done.returncode}"]
        row["error"] = lines[-1]
        return row
    result = json.loads(done.stdout)
    row.update({key: result[key] for key in BENCH_KEYS})
    row["build_s_per_creature"] = result["build_s"] / creatures
    row["frame_ms_per_creature"] = result["frame_ms"] / creatures
    return row


def write_csv(rows: list[dict[str, Any]], path: Path) -> None:
    with atomic_output(path) as temporary, open(temporary, "w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=COLUMNS, restval="")
        writer.writeheader()
        writer.writerows(rows)


def plot(rows: list[dict[str, Any]], path: Path) -> None:
    """Build seconds and frame ms per creature against creatures, a line per thread count."""
    figure = Figure(figsize=(10, 4.2), layout="constrained")
    build, frame = figure.subplots(1, 2)
    for threads in sorted({row["threads"] for row in rows}):
        ok = [r for r in rows if r["threads"] == threads and not r["error"]]
        sizes = [r["creatures"] for r in ok]
        label = f"{threads} thread" + ("s" if threads > 1 else "")
        build.plot(sizes, [r["build_s"] for r in ok], marker="o", label=label)
        frame.plot(sizes, [r["frame_ms_per_creature"] for r in ok], marker="o", label=label)
    plain = FuncFormatter(lambda value, _: f"{value:g}")
    sizes = sorted({row["creatures"] for row in rows})
    for axes, title in ((build, "build (s)"), (frame, "frame ms per creature")):
        axes.set_xscale("log")
        axes.set_xticks(sizes, [str(n) for n in sizes])
        axes.xaxis.set_minor_formatter(NullFormatter())
        axes.set_xlabel("creatures")
        axes.set_title(title)
        axes.grid(True, which="both", alpha=0.3)
        axes.legend()
    build.set_yscale("log")
    build.yaxis.set_major_formatter(plain)
    build.yaxis.set_minor_formatter(plain)
    figure.suptitle("ecs-tentacles bench --crowd N")
    with atomic_output(path) as temporary:
        figure.savefig(temporary, dpi=110)


def number_list(text: str) -> list[int]:
    """argparse type: comma-separated whole numbers >= 1."""
    try:
        values = [int(part) for part in text.split(",")]
    except ValueError:
        message = f"must be whole numbers like 1,4,16, got {text!r}"
        raise argparse.ArgumentTypeError(message) from None
    if not values or min(values) < 1:
        raise argparse.ArgumentTypeError(f"every number must be >= 1, got {text!r}")
    return values


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--sizes", type=number_list, default=list(SIZES), help="creature counts")
    cores = os.cpu_count() or 1
    parser.add_argument(
        "--threads",
        type=number_list,
        default=sorted({1, cores}),
        help=f"thread counts (default 1 and all cores: {sorted({1, cores})})",
    )
    parser.add_argument("--frames", type=int, default=120, help="timed frames per run")
    parser.add_argument("--seed", type=int, default=0, help="crowd seed")
    parser.add_argument(
        "--uniform", action="store_true", help="crowds of 8 x 10 octopuses (one morphology)"
    )
    parser.add_argument("--idle", type=float, default=0.0, help="fraction of idle creatures")
    parser.add_argument("--timeout", type=float, default=3600.0, help="seconds allowed per run")
    parser.add_argument(
        "--out", type=Path, default=Path("crowd_scaling"), help="writes OUT.csv and OUT.png"
    )
    args = parser.parse_args(argv)
    runs = [(n, t) for n in args.sizes for t in args.threads]
    rows = []
    for i, (creatures, threads) in enumerate(runs, 1):
        print(f"[{i}/{len(runs)}] {creatures} creatures, {threads} threads ...", file=sys.stderr)
        extra = ("--idle", str(args.idle)) + (("--uniform",) if args.uniform else ())
        row = bench_once(creatures, threads, args.frames, args.seed, args.timeout, extra)
        rows.append(row)
        if row["error"]:
            print(f"    failed: {row['error']}", file=sys.stderr)
        else:
            print(
                f"    build {row['build_s']:.2f} s, {row['frame_ms']:.2f} ms/frame"
                f" ({row['frame_ms_per_creature']:.3f} per creature), overhead"
                f" {row['overhead_ratio']:.3f}x, {row['rss_mb']:.0f} MB",
                file=sys.stderr,
            )
    csv_path, png_path = args.out.with_suffix(".csv"), args.out.with_suffix(".png")
    write_csv(rows, csv_path)
    plot(rows, png_path)
    print(f"wrote {csv_path} and {png_path}", file=sys.stderr)
    return 1 if any(row["error"] for row in rows) else 0


if __name__ == "__main__":
    sys.exit(main())
