"""Soak test: run a command (a headless simulation) for a while and watch its memory.

    python tools/soak.py --crowd 64 --terrain rocky --minutes 30
    python tools/soak.py --scene octopus --minutes 5 --every 10
    python tools/soak.py --minutes 60 -- ecs-tentacles bake crowd.json --seconds 900 --out t.npz
    python tools/soak.py --crowd 64 --terrain rocky --minutes 30 --in-process

The command runs in a process of its own (`--crowd N` writes that crowd scene with
`ecs-tentacles crowd` and runs it; `--scene` runs a scene file or bundled scene:
`ecs-tentacles run SCENE --frames <many> --quiet --threads T`). Its resident set size
(psutil; `--tree` adds its descendants') is sampled every `--every` seconds until
`--minutes` have passed, then the command is stopped (SIGTERM) if it still runs.

`--in-process` builds the scene in this process instead and steps it here (`World.step`,
what `run` does), so each frame is timed as well: every row then also gives the median
frame time of the frames since the last sample, and the verdict the median frame time of
the first and of the last window.

The table lists every sample: seconds since the start, RSS, and RSS against the first
sample after `--warmup` seconds (building the scene and the first frames grow a process
for real). The verdict compares the floor (lowest sample) of the last window with the
floor of the first window after the warm-up (windows of a tenth of the run, at least a
minute) against `--threshold` MB: exit 0 within it, 1 over it or when the command
failed. Floors, because a sample may fall inside a frame: a crowd's frame holds tens of
MB of temporaries while it runs and gives them back at its end, so single samples spike
(the verdict line gives the highest) while what a process keeps, and what a leak or a
fragmented heap adds to, is the level it returns to. The floor's least-squares slope
(MB per hour) and the last window's median are given too.
"""

from __future__ import annotations

import argparse
import os
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import psutil

MB = 1024.0**2


def resident(process: psutil.Process, tree: bool) -> float:
    """RSS of `process` (and its descendants with `tree`) in MB."""
    processes = [process, *process.children(recursive=True)] if tree else [process]
    total = 0
    for p in processes:
        try:
            total += p.memory_info().rss
        except psutil.Error:
            continue
    return total / MB


def command_of(args: argparse.Namespace, folder: Path) -> list[str]:
    """The command to soak: the one given after `--`, or `run` of the scene / crowd."""
    if args.command:
        return args.command
    frames = ["--frames", "1000000", "--quiet", "--threads", str(args.threads)]
    return [*CLI, "run", scene_of(args, folder), *frames]


CLI = [sys.executable, "-P", "-m", "ecs_tentacles"]


def scene_of(args: argparse.Namespace, folder: Path) -> str:
    """The scene to soak: `--scene`, or the crowd of `--crowd` written into `folder`."""
    if args.crowd is None:
        return str(args.scene)
    scene = str(folder / f"crowd{args.crowd}.json")
    write = [*CLI, "crowd", str(args.crowd), "--out", scene, "--seed", str(args.seed)]
    subprocess.run([*write, "--terrain", args.terrain], check=True, stdout=subprocess.DEVNULL)
    return scene


def window(samples: list[tuple[float, float]], start: float, end: float) -> list[float]:
    return [rss for t, rss in samples if start <= t <= end]


def verdict(
    samples: list[tuple[float, float]], warmup: float, threshold: float
) -> tuple[bool, str]:
    """(within the threshold, the verdict line) from (seconds, MB) samples: the floor of
    the first window after the warm-up against the floor of the last (see the module doc)."""
    after = [(t, rss) for t, rss in samples if t >= warmup]
    if len(after) < 2:
        return False, "FAIL: fewer than two samples after the warm-up (run longer)"
    first_t, last_t = after[0][0], after[-1][0]
    span = min(max(60.0, (last_t - first_t) / 10), (last_t - first_t) / 4)
    base = min(window(after, first_t, first_t + span))
    end = min(window(after, last_t - span, last_t))
    median = statistics.median(window(after, last_t - span, last_t))
    peak_t, peak = max(after, key=lambda s: s[1])
    ends = [s for s, _ in after if s >= first_t + span]  # full windows only
    floor = [min(window(after, s - span, s)) for s in ends]
    slope = float(np.polyfit(ends, floor, 1)[0]) * 3600.0 if len(ends) > 1 else 0.0
    growth = end - base
    ok = growth <= threshold
    word = "PASS" if ok else "FAIL"
    return ok, (
        f"{word}: resident memory after warm-up (floor of {span:.0f} s windows)"
        f" {base:.1f} -> {end:.1f} MB ({growth:+.1f} MB over {(last_t - first_t) / 60:.1f} min,"
        f" threshold +{threshold:g} MB); floor slope {slope:+.2f} MB/h; last window's median"
        f" {median:.1f} MB ({median - base:+.1f}); peak {peak:.1f} MB at {peak_t:.0f} s"
        f" ({peak - base:+.1f}: memory a frame holds while it runs)"
    )


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    what = parser.add_mutually_exclusive_group()
    what.add_argument("--crowd", type=int, metavar="N", help="run a crowd scene of N creatures")
    what.add_argument("--scene", default="octopus", help="scene file or bundled scene to run")
    parser.add_argument("--terrain", default="rocky", help="the crowd's ground (default rocky)")
    parser.add_argument("--seed", type=int, default=0, help="the crowd's seed (default 0)")
    parser.add_argument("--threads", type=int, default=1, help="stepping threads (default 1)")
    parser.add_argument("--minutes", type=float, default=30.0, help="how long (default 30)")
    parser.add_argument("--every", type=float, default=30.0, help="seconds between samples")
    parser.add_argument("--warmup", type=float, default=180.0, help="seconds not judged")
    parser.add_argument("--threshold", type=float, default=5.0, help="MB allowed to grow")
    parser.add_argument("--tree", action="store_true", help="add the descendants' RSS")
    parser.add_argument(
        "--in-process", action="store_true", help="step the scene here, timing every frame"
    )
    parser.add_argument("command", nargs="*", help="the command to soak (after --)")
    args = parser.parse_args(argv)
    if args.in_process:
        return soak_here(args)

    with tempfile.TemporaryDirectory(prefix="soak-") as tmp:
        command = command_of(args, Path(tmp))
        print(f"soak: {' '.join(command)}", flush=True)
        print(
            f"soak: {args.minutes:g} min, a sample every {args.every:g} s,"
            f" warm-up {args.warmup:g} s, threshold +{args.threshold:g} MB",
            flush=True,
        )
        with open(Path(tmp) / "output.txt", "w+") as log:
            child = subprocess.Popen(command, stdout=log, stderr=subprocess.STDOUT)
            samples, ended = sample(child, args)
            log.seek(0)
            tail = log.read().splitlines()[-5:]
    if ended:
        print(f"FAIL: the command ended early (exit {child.returncode}):", *tail, sep="\n")
        return 1
    ok, line = verdict(samples, args.warmup, args.threshold)
    print(line, flush=True)
    return 0 if ok else 1


def sample(
    child: subprocess.Popen[bytes], args: argparse.Namespace
) -> tuple[list[tuple[float, float]], bool]:
    """(seconds, MB) samples of `child` until the time is up, a row printed for each; then
    the child is stopped. Also whether it ended by itself before that."""
    process = psutil.Process(child.pid)
    start = time.monotonic()
    samples: list[tuple[float, float]] = []
    print(f"{'seconds':>8} {'RSS MB':>9} {'vs base':>8}", flush=True)
    try:
        while (now := time.monotonic() - start) < args.minutes * 60:
            if child.poll() is not None:
                break
            rss = resident(process, args.tree)
            samples.append((now, rss))
            after = window(samples, args.warmup, now)
            base = f"{rss - after[0]:+8.1f}" if after else f"{'':>8}"
            print(f"{now:8.0f} {rss:9.1f} {base}", flush=True)
            time.sleep(max(0.0, args.every - (time.monotonic() - start - now)))
    finally:
        ended = child.poll() is not None
        if not ended:
            child.send_signal(signal.SIGTERM)
            try:
                child.wait(timeout=30)
            except subprocess.TimeoutExpired:
                child.kill()
                child.wait()
    return samples, ended


def soak_here(args: argparse.Namespace) -> int:
    """`--in-process`: build the scene (or crowd) here and step it, sampling this process's
    RSS and the frames' times; the verdict adds the median frame time at start and end.
    Only the frames since the last sample are kept (a list of every frame's time would
    itself grow the process by about 0.2 MB a minute)."""
    from ecs_tentacles.world import World

    with tempfile.TemporaryDirectory(prefix="soak-") as tmp:
        scene = scene_of(args, Path(tmp))
        print(f"soak: {scene} stepped in this process, {args.threads} thread(s)", flush=True)
        world = World.from_scene(scene, threads=args.threads)
    process = psutil.Process()
    samples: list[tuple[float, float]] = []
    medians: list[tuple[float, float]] = []  # (seconds, median frame ms since the last sample)
    recent = np.empty(1 << 16)  # frame times since the last sample, ms
    count = 0
    print(f"{'seconds':>8} {'RSS MB':>9} {'vs base':>8} {'frame ms':>9} {'frames':>7}", flush=True)
    start = last = time.monotonic()
    with world:
        while (now := time.monotonic() - start) < args.minutes * 60:
            began = time.perf_counter()
            world.step()
            recent[count % len(recent)] = (time.perf_counter() - began) * 1000.0
            count += 1
            if time.monotonic() - last >= args.every or not samples:
                last = time.monotonic()
                rss = resident(process, args.tree)
                samples.append((now, rss))
                median = float(np.median(recent[: min(count, len(recent))]))
                medians.append((now, median))
                after = window(samples, args.warmup, now)
                base = f"{rss - after[0]:+8.1f}" if after else f"{'':>8}"
                print(f"{now:8.0f} {rss:9.1f} {base} {median:9.2f} {count:7d}", flush=True)
                count = 0
    ok, line = verdict(samples, args.warmup, args.threshold)
    print(line, flush=True)
    warm = [(t, ms) for t, ms in medians if t >= args.warmup]
    if len(warm) > 1:
        first_t, last_t = warm[0][0], warm[-1][0]
        span = min(max(60.0, (last_t - first_t) / 10), (last_t - first_t) / 4)
        head = statistics.median(ms for t, ms in warm if t <= first_t + span)
        tail = statistics.median(ms for t, ms in warm if t >= last_t - span)
        print(
            f"frame time after warm-up (median of the rows in the first and last {span:.0f} s):"
            f" {head:.2f} ms at the start, {tail:.2f} ms at the end ({tail / head:.3f}x)",
            flush=True,
        )
    return 0 if ok else 1


if __name__ == "__main__":
    os.environ.setdefault("PYTHONUNBUFFERED", "1")
    sys.exit(main())
