"""Benchmark: `ecs-tentacles export TAKE --out X.usdc` as an artist runs it, one run.

    python tools/bench_usd_export.py u1024.npz                 # export, then measure
    python tools/bench_usd_export.py u64.npz --validate --json
    python tools/bench_usd_export.py u64.npz --python /old/venv/bin/python   # another tree

The export runs in its own process under `/usr/bin/time -v`: wall time and peak RSS are
the whole command's (reading the take included). Then, from the file: its size, the
bytes per creature-frame, how many replayed stretches bind a shared clip animation
(their SkelAnimation references one under the stage's clips) and how many animations
are the creatures' own (one each: their physical frames), and
with `--validate` the validators' errors and warnings (`export --validate`, every USD
validator, UsdSkel's included). One run each: state the machine's load (`uptime`).

Measured (one run each; `crowd N --uniform --seed 3`, `bake --seconds 30 --fps 24`, 721
frames; export alone, then `usd_problems` on the file):

    1,024 creatures, load 14-15: 142 s, peak 803 MB, 371 MB (503 B a creature-frame),
        1,503 replayed stretches of 1,024 creatures sharing one clip animation, 1,024
        own animations (sampled at their physical frames only); validators 0 errors
        (50 s, 220 MB). Through UsdSkel.Cache, the skeleton shown within 0.003 mm of
        the take at every frame (23 creatures, the 12 that switch most among them).
        Before (6dd3c68, run just before, load 12-14): 128 s, peak 784 MB, 753 MB
        (1,020 B), 522 creatures sharing, 502 alone; before that (cb9ca9a, the issue's
        figure, 5 s at 60 fps): 3 min 10 s, 6.56 GB, 1.07 GB (3.5 KB a creature-frame).
        Reading the take alone (open_take, every chunk) takes 26 s and 483 MB at load 3;
        under load it is 40 % of the export (filling replayed bodies from their clip).
    64 creatures (all within the full and reduced budgets: none replayed), load 3.4,
        with --validate: 4.5 s, peak 473 MB, 71 MB (1,547 B); 0 errors. Before (d5bb160,
        the same scene's version 1 take): 12.2 s, peak 909 MB, 138 MB (3,000 B).

Where the 1,024 crowd's bytes go: swaying fur guides (169 MB: a cat's guides move more
than 0.5 mm every frame; stiff fur is written once); the physical creature-frames' 81
quaternions (107 thousand samples, 138 MB); root motion (translate float3, rotateZ:
30 MB); the shared clip (2,367 clip frames, 3 MB); the rest is the file's index,
rewritten at each of its saves.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any


def shared(path: Path) -> tuple[int, int]:
    """(animations referencing a shared clip: a replayed stretch each, animations of
    their own)."""
    from pxr import Usd, UsdSkel

    stage = Usd.Stage.Open(str(path))
    sharing = alone = 0
    for prim in stage.Traverse():
        if prim.IsA(UsdSkel.Animation):
            if prim.GetPrimStack()[0].referenceList.GetAddedOrExplicitItems():
                sharing += 1
            else:
                alone += 1
    return sharing, alone


def measure(take: Path, out: Path, python: str, validate: bool) -> dict[str, Any]:
    """Export `take` to `out` with `python`; what it cost and what it made."""
    from ecs_tentacles.take import Take

    header = Take.read_header(take)
    argv = [python, "-m", "ecs_tentacles", "export", str(take), "--out", str(out), "--quiet"]
    done = subprocess.run(
        ["/usr/bin/time", "-v", *argv, *(["--validate"] if validate else [])],
        capture_output=True,
        text=True,
    )
    if done.returncode not in (0, 1):  # 1: --validate found an error
        raise SystemExit(f"export failed ({done.returncode}): {done.stderr[-2000:]}")
    wall = re.search(r"Elapsed \(wall clock\) time .*: (?:(\d+):)?(\d+):([\d.]+)", done.stderr)
    peak = re.search(r"Maximum resident set size \(kbytes\): (\d+)", done.stderr)
    assert wall is not None and peak is not None, done.stderr
    hours, minutes, seconds = (float(x or 0) for x in wall.groups())
    size = out.stat().st_size
    creatures, frames = len(header["creatures"]), int(header["frames"])
    row: dict[str, Any] = {
        "take": str(take),
        "creatures": creatures,
        "frames": frames,
        "fps": header["fps"],
        "wall_s": round(3600 * hours + 60 * minutes + seconds, 1),
        "peak_rss_mb": round(int(peak.group(1)) / 1024),
        "file_mb": round(size / 1e6, 1),
        "bytes_per_creature_frame": round(size / (creatures * frames)),
    }
    row["sharing"], row["own_animation"] = shared(out)
    if validate:
        line = next(t for t in done.stderr.splitlines() if "USD validation:" in t)
        counts = re.findall(r"(\d+) (error|warning)", line)
        row.update({f"{kind}s": int(n) for n, kind in counts})
    return row


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("takes", nargs="+", type=Path, metavar="TAKE")
    parser.add_argument("--python", default=sys.executable, help="the Python that exports")
    parser.add_argument("--validate", action="store_true", help="count the validators' errors")
    parser.add_argument("--keep", type=Path, help="folder to keep the .usdc files in")
    parser.add_argument("--json", action="store_true", help="one JSON object a take")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory(dir=args.keep) as scratch:
        folder = args.keep or Path(scratch)
        for take in args.takes:
            row = measure(take, folder / f"{take.stem}.usdc", args.python, args.validate)
            if args.json:
                print(json.dumps(row), flush=True)
            else:
                print(
                    f"{take.name}: {row['creatures']} creatures x {row['frames']} frames at"
                    f" {row['fps']:g} fps: {row['wall_s']} s, peak {row['peak_rss_mb']} MB,"
                    f" {row['file_mb']} MB ({row['bytes_per_creature_frame']} B a creature-"
                    f"frame), {row['sharing']} stretches sharing a clip,"
                    f" {row['own_animation']} own animations"
                    + (f", {row['errors']} errors" if "errors" in row else ""),
                    flush=True,
                )
    print(f"load: {os.getloadavg()[0]:.2f}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
