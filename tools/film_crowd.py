"""Benchmark: a film crowd from scene to files, by crowd size, as an artist runs it.

    python tools/film_crowd.py                              # 64 and 1,024 creatures, 30 s
    python tools/film_crowd.py --sizes 10000 --seconds 5 --json
    python tools/film_crowd.py --sizes 1024 --steps bake,run --seconds 120

For each size: `ecs-tentacles crowd N --uniform --seed 3`, then each step as its own
process, timed (wall) with its peak memory (the child's max RSS, `os.wait4`):

    bake     bake --seconds S --fps 24 --out crowd.npz   (the take: MB a simulated second,
             bytes per creature-frame)
    run      run --frames S*60 (the same simulated seconds, nothing recorded): the bake's
             wall over this is what recording and writing cost
    usd      export crowd.npz --out crowd.usdc (MB, bytes per creature-frame)
    blender  the crowd take opened by the Blender add-on in a Python with bpy
             ($ECS_TENTACLES_BLENDER_PYTHON), when there is one (`ecs-tentacles
             blender-addon --install` into a fresh Blender user folder first)

One run each: state the machine's load (printed) beside the figures.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

STEPS = ("bake", "run", "usd", "blender")


def timed(argv: list[str], cwd: Path, env: dict[str, str] | None = None) -> dict[str, Any]:
    """Run `argv`; wall seconds, peak RSS (MB) and exit code."""
    start = time.perf_counter()
    process = subprocess.Popen(
        argv, cwd=cwd, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE
    )
    _, status, usage = os.wait4(process.pid, 0)
    wall = time.perf_counter() - start
    out = process.stdout.read().decode() if process.stdout else ""
    err = process.stderr.read().decode() if process.stderr else ""
    code = os.waitstatus_to_exitcode(status)
    if code != 0:
        print(f"{' '.join(argv)}: exit {code}\n{err[-2000:]}", file=sys.stderr)
    return {"wall_s": round(wall, 2), "rss_mb": round(usage.ru_maxrss / 1024, 1), "exit": code,
            "stdout": out[-400:]}  # fmt: skip


def cli(*args: str) -> list[str]:
    return [sys.executable, "-P", "-m", "ecs_tentacles", *args]


def one_size(count: int, seconds: float, steps: list[str], folder: Path) -> dict[str, Any]:
    scene = folder / f"u{count}.json"
    subprocess.run(cli("crowd", str(count), "--uniform", "--seed", "3", "--out", str(scene)),
                   check=True, capture_output=True)  # fmt: skip
    take, usd = folder / f"u{count}.npz", folder / f"u{count}.usdc"
    frames = round(seconds * 24) + 1
    row: dict[str, Any] = {"creatures": count, "seconds": seconds, "take_frames": frames}
    if "bake" in steps:
        row["bake"] = timed(cli("bake", str(scene), "--seconds", str(seconds), "--fps", "24",
                                "--quiet", "--out", str(take)), folder)  # fmt: skip
        if row["bake"]["exit"] != 0:  # refused (its line is on stderr): nothing to measure
            return row
        size = take.stat().st_size
        row["take_mb_per_s"] = round(size / 1e6 / seconds, 2)
        row["take_bytes_per_creature_frame"] = round(size / (count * frames), 1)
    if "run" in steps:
        row["run"] = timed(cli("run", str(scene), "--frames", str(round(seconds * 60)),
                               "--quiet"), folder)  # fmt: skip
        if "bake" in row:
            row["bake_over_run"] = round(row["bake"]["wall_s"] / row["run"]["wall_s"], 2)
    if "usd" in steps and take.exists():
        row["usd"] = timed(cli("export", str(take), "--out", str(usd), "--quiet"), folder)
        if usd.exists():
            row["usd_mb"] = round(usd.stat().st_size / 1e6, 1)
            row["usd_bytes_per_creature_frame"] = round(usd.stat().st_size / (count * frames), 1)
    blender = os.environ.get("ECS_TENTACLES_BLENDER_PYTHON")
    if "blender" in steps and blender and take.exists():
        user = folder / "blender_user"  # a Blender user folder with the add-on installed
        env = {**os.environ, "BLENDER_USER_RESOURCES": str(user)}
        subprocess.run(cli("blender-addon", "--install", "--blender", blender), env=env,
                       check=True, capture_output=True)  # fmt: skip
        script = (
            "import sys, bpy; bpy.ops.wm.read_userpref();"
            " bpy.ops.import_scene.ecs_tentacles_take(filepath=sys.argv[1])"
        )
        row["blender"] = timed([blender, "-c", script, str(take)], folder, env)
    return row


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--sizes", default="64,1024")
    parser.add_argument("--seconds", type=float, default=30.0)
    parser.add_argument("--steps", default=",".join(STEPS))
    parser.add_argument("--folder", type=Path, default=None, help="keep the files here")
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args(argv)
    steps = args.steps.split(",")
    load = os.getloadavg()
    rows = []
    with tempfile.TemporaryDirectory() as scratch:
        folder = args.folder or Path(scratch)
        folder.mkdir(parents=True, exist_ok=True)
        for count in (int(s) for s in args.sizes.split(",")):
            rows.append(one_size(count, args.seconds, steps, folder))
            if not args.json:
                print(json.dumps(rows[-1], indent=1), flush=True)
    result = {"load_before": [round(x, 2) for x in load],
              "load_after": [round(x, 2) for x in os.getloadavg()], "rows": rows}  # fmt: skip
    print(json.dumps(result) if args.json else f"load {result['load_before']} -> "
          f"{result['load_after']}")  # fmt: skip
    return 0


if __name__ == "__main__":
    sys.exit(main())
