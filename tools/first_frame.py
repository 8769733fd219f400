"""Benchmark: from the start of a crowd's build to the end of its first frame, by cache.

    python tools/first_frame.py                       # 1,024 uniform octopuses (seed 3)
    python tools/first_frame.py --crowd 10000 --caches warm --json

Writes `ecs-tentacles crowd N --uniform --seed S` to a temporary folder, then runs
`ecs-tentacles run SCENE --frames 1 --json` in a fresh process per cache state and
reports its `build_seconds`, its first frame (`wall_seconds`) and their sum (the time
from the build's start to the end of the first frame), with the process's CPU seconds
(user + system, the stepping threads' too) that a shared machine moves less.

The caches a first frame meets:
* the gait clips kept on disk (`ecs_tentacles.clips.disk`): a replayed morphology is
  recorded on its first frame unless an earlier run of the same code kept its clips;
* numba's compiled kernels (``cache=True``: beside the sources, or `NUMBA_CACHE_DIR`).

One untimed run fills both first; `warm` then finds both filled, `cold-clips` an empty
clip cache (`XDG_CACHE_HOME`), `cold-numba` an empty numba cache (`NUMBA_CACHE_DIR`),
`cold` both empty. Every cache lives in the temporary folder: the user's are
neither read nor written. One run each: state the machine's load (`uptime`).
"""

from __future__ import annotations

import argparse
import json
import os
import pathlib
import resource
import subprocess
import sys
import tempfile
from typing import Any

CACHES = ("warm", "cold-clips", "cold-numba", "cold")


def run_once(scene: pathlib.Path, env: dict[str, str]) -> dict[str, Any]:
    """One `ecs-tentacles run SCENE --frames 1 --json` in a fresh process."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    done = subprocess.run(
        [sys.executable, "-m", "ecs_tentacles", "run", str(scene), "--frames", "1", "--json",
         "--quiet"],
        env=env, capture_output=True, text=True, check=True,
    )  # fmt: skip
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    report = json.loads(done.stdout)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    build, frame = report["build_seconds"], report["wall_seconds"]
    return {
        "build_s": round(build, 3),
        "first_frame_s": round(frame, 3),
        "to_first_frame_s": round(build + frame, 3),
        "process_cpu_s": round(cpu, 3),
    }


def measure(crowd: int, seed: int, caches: list[str]) -> dict[str, Any]:
    """Each cache state's figures for a uniform crowd of `crowd` (seed `seed`)."""
    results: dict[str, Any] = {"crowd": crowd, "seed": seed, "load": os.getloadavg()[0]}
    with tempfile.TemporaryDirectory(prefix="first_frame_") as folder:
        root = pathlib.Path(folder)
        scene = root / "crowd.json"
        subprocess.run(
            [sys.executable, "-m", "ecs_tentacles", "crowd", str(crowd), "--uniform", "--seed",
             str(seed), "--out", str(scene)],
            check=True, capture_output=True,
        )  # fmt: skip
        warm = {"XDG_CACHE_HOME": str(root / "clips"), "NUMBA_CACHE_DIR": str(root / "numba")}
        run_once(scene, {**os.environ, **warm})  # untimed: fills the warm caches
        for i, cache in enumerate(caches):
            env = {**os.environ, **warm}
            if cache in ("cold-clips", "cold"):
                env["XDG_CACHE_HOME"] = str(root / f"clips-cold{i}")
            if cache in ("cold-numba", "cold"):
                env["NUMBA_CACHE_DIR"] = str(root / f"numba-cold{i}")
            results[cache] = run_once(scene, env)
    return results


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--crowd", type=int, default=1024, help="uniform creatures (1024)")
    parser.add_argument("--seed", type=int, default=3, help="the crowd's seed (3)")
    parser.add_argument(
        "--caches", nargs="+", choices=CACHES, default=list(CACHES), help="cache states to time"
    )
    parser.add_argument("--json", action="store_true", help="one JSON object")
    args = parser.parse_args(argv)
    results = measure(args.crowd, args.seed, args.caches)
    if args.json:
        print(json.dumps(results))
        return 0
    print(f"{args.crowd} uniform creatures (seed {args.seed}), load {results['load']:.2f}")
    for cache in args.caches:
        r = results[cache]
        print(
            f"  {cache:10s} build {r['build_s']:.2f} s + first frame {r['first_frame_s']:.2f} s"
            f" = {r['to_first_frame_s']:.2f} s ({r['process_cpu_s']:.2f} s CPU, whole process)"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
