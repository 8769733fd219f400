"""Crowd scaling: frame cost per creature and memory, 16 to 10,000 creatures, LOD on and off.

    python tools/crowd_scaling.py              # 16 64 256 1024 10000, lod on/off, 1 and all threads
    python tools/crowd_scaling.py --sizes 1,4,16 --lod off --frames 60 --out build/scaling

Each (creatures, lod, threads) run is `ecs-tentacles bench --crowd N --lod L --threads T
--json` (uniform crowds unless `--varied`) in a fresh process, so one size's memory and
compiled models never weigh on the next. Writes `<out>.csv` (one row per run, with the
creatures per physics tier and the promotions at the end; a failed or timed-out run
keeps its error and leaves the numbers empty) and `<out>.png`: frame ms per creature
and resident memory (MB) against creatures (log x), one line per (lod, threads).
Progress goes to stderr.
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

from ecs_tentacles.output.atomic import atomic_output

LOD_OFF_MAX = 1024
SIZES = (16, 64, 256, 1024, 10000)
LODS = ("on", "off")
TIERS = ("full", "reduced", "kinematic")
# untimed frames before timing: every creature starts FULL and is demoted only after
# `physics.lod.hold_seconds` (1 s, 60 frames), so the timing starts after that
WARMUP = 90
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
    "lod",
    "threads",
    *BENCH_KEYS[:3],
    "build_s_per_creature",
    "frame_ms",
    "frame_ms_per_creature",
    *BENCH_KEYS[4:],
    *TIERS,
    "promotions",
    "error",
)


def bench_once(
    creatures: int,
    threads: int,
    frames: int,
    seed: int,
    timeout: float,
    extra: tuple[str, ...] = (),
    lod: str = "on",
) -> dict[str, Any]:
    """One CSV row: `ecs-tentacles bench --crowd --lod` (+ `extra` options) in a fresh
    process, killed after `timeout` seconds (the row then says so)."""
    command = [sys.executable, "-m", "ecs_tentacles.cli", "bench", "--crowd", str(creatures)]
    command += ["--threads", str(threads), "--frames", str(frames), "--seed", str(seed), "--json"]
    command += ["--lod", lod, "--quiet", *extra]
    row: dict[str, Any] = {"creatures": creatures, "lod": lod, "threads": threads, "error": ""}
    try:
        done = subprocess.run(command, capture_output=True, text=True, timeout=timeout, check=False)
    except subprocess.TimeoutExpired:
        row["error"] = f"timed out after {timeout:g} s (--timeout)"
        return row
    if done.returncode != 0:
        lines = done.stderr.strip().splitlines() or [f"exit code {done.returncode}"]
        row["error"] = lines[-1]
        return row
    result = json.loads(done.stdout)
    row.update({key: result[key] for key in BENCH_KEYS})
    row.update({tier: result["tiers"][tier] for tier in TIERS})
    row["promotions"] = result["promotions"]
    row["build_s_per_creature"] = result["build_s"] / creatures
    row["frame_ms_per_creature"] = result["frame_ms"] / creatures
    return row


def write_csv(rows: list[dict[str, Any]], path: Path) -> None:
    with atomic_output(path) as temporary, open(temporary, "w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=COLUMNS, restval="")
        writer.writeheader()
        writer.writerows(rows)


def plot(rows: list[dict[str, Any]], path: Path) -> None:
    """Frame ms per creature and resident MB against creatures, a line per (lod, threads)."""
    figure = Figure(figsize=(10, 4.2), layout="constrained")
    frame, memory = figure.subplots(1, 2)
    runs = sorted({(row["lod"], row["threads"]) for row in rows})
    colours = {t: f"C{i}" for i, t in enumerate(sorted({t for _, t in runs}))}
    for lod, threads in runs:
        ok = [r for r in rows if (r["lod"], r["threads"]) == (lod, threads) and not r["error"]]
        sizes = [r["creatures"] for r in ok]
        style = {
            "marker": "o",
            "color": colours[threads],
            "linestyle": "-" if lod == "on" else "--",
            "label": f"lod {lod}, {threads} thread" + ("s" if threads > 1 else ""),
        }
        frame.plot(sizes, [r["frame_ms_per_creature"] for r in ok], **style)
        memory.plot(sizes, [r["rss_mb"] for r in ok], **style)
    plain = FuncFormatter(lambda value, _: f"{value:g}")
    sizes = sorted({row["creatures"] for row in rows})
    for axes, title in ((frame, "frame ms per creature"), (memory, "resident memory (MB)")):
        axes.set_xscale("log")
        axes.set_xticks(sizes, [str(n) for n in sizes])
        axes.xaxis.set_minor_formatter(NullFormatter())
        axes.set_xlabel("creatures")
        axes.set_title(title)
        axes.grid(True, which="both", alpha=0.3)
        axes.legend()
    if any(not row["error"] for row in rows):  # a log scale needs a value
        memory.set_yscale("log")
        memory.yaxis.set_major_formatter(plain)
        memory.yaxis.set_minor_formatter(plain)
    figure.suptitle("ecs-tentacles bench --crowd N --lod on|off")
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


def lod_list(text: str) -> list[str]:
    """argparse type: `on`, `off` or `on,off`."""
    values = text.split(",")
    if not values or any(value not in LODS for value in values):
        raise argparse.ArgumentTypeError(f"must be on, off or on,off, got {text!r}")
    return list(dict.fromkeys(values))


def build_parser() -> argparse.ArgumentParser:
    """The tool's arguments (the docs tests parse the handbook's lines with it)."""
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
        "--lod", type=lod_list, default=list(LODS), help="level of detail: on, off or on,off"
    )
    parser.add_argument(
        "--varied",
        action="store_true",
        help="varied body plans (default: uniform crowds of 8 x 10 octopuses, one morphology)",
    )
    parser.add_argument("--uniform", action="store_true", help="uniform crowds (the default)")
    parser.add_argument("--idle", type=float, default=0.0, help="fraction of idle creatures")
    parser.add_argument(
        "--timeout", type=float, default=3600.0, help="seconds allowed per run (default 3600)"
    )
    parser.add_argument(
        "--warmup",
        type=int,
        default=WARMUP,
        help=f"untimed frames first (default {WARMUP}: past lod's first demotions)",
    )
    parser.add_argument(
        "--lod-off-max",
        type=int,
        default=LOD_OFF_MAX,
        help=f"largest crowd run with lod off (default {LOD_OFF_MAX}: 10,000 creatures at"
        " full physics take about 10 s a frame)",
    )
    parser.add_argument(
        "--out", type=Path, default=Path("crowd_scaling"), help="writes OUT.csv and OUT.png"
    )
    return parser


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    runs = [
        (n, lod, t)
        for n in args.sizes
        for lod in args.lod
        for t in args.threads
        if lod == "on" or n <= args.lod_off_max
    ]
    rows = []
    extra: tuple[str, ...] = ("--idle", str(args.idle), "--warmup", str(args.warmup))
    extra += () if args.varied else ("--uniform",)
    for i, (creatures, lod, threads) in enumerate(runs, 1):
        print(
            f"[{i}/{len(runs)}] {creatures} creatures, lod {lod}, {threads} threads ...",
            file=sys.stderr,
        )
        row = bench_once(creatures, threads, args.frames, args.seed, args.timeout, extra, lod)
        rows.append(row)
        if row["error"]:
            print(f"    failed: {row['error']}", file=sys.stderr)
        else:
            print(
                f"    build {row['build_s']:.2f} s, {row['frame_ms']:.2f} ms/frame"
                f" ({row['frame_ms_per_creature']:.3f} per creature), overhead"
                f" {row['overhead_ratio']:.3f}x, {row['rss_mb']:.0f} MB; tiers"
                f" {'/'.join(str(row[t]) for t in TIERS)}, {row['promotions']} promotions",
                file=sys.stderr,
            )
    csv_path, png_path = args.out.with_suffix(".csv"), args.out.with_suffix(".png")
    write_csv(rows, csv_path)
    plot(rows, png_path)
    print(f"wrote {csv_path} and {png_path}", file=sys.stderr)
    return 1 if any(row["error"] for row in rows) else 0


if __name__ == "__main__":
    sys.exit(main())
