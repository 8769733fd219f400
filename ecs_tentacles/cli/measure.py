"""Headless benchmark of a world: build time, frame time, and MuJoCo stepped bare.

    from ecs_tentacles.cli.measure import bench
    from ecs_tentacles.creator.crowd import crowd_scene
    result = bench(crowd_scene(16), frames=120, threads=2)
    print(result["frame_ms"], result["raw_mujoco_ms"], result["overhead_ratio"])

How `bench` measures (every figure is milliseconds per frame, the median over blocks):

* `build_s`: `World.from_scene` (validate, build entities, compile, schedule).
* After `warmup` untimed frames, the run alternates blocks of `block` framework
  frames (`world.step`) with blocks of as many bare frames. Each framework frame's
  stepping inputs are captured just before its step (`ecs_tentacles.physics.bare`:
  every stepped row's state and overlay; the capture's own time is taken out of the
  frame's and the physics system's); a bare block steps the last captured block's
  frames with MuJoCo alone (`mj_setState`, `mj_step`, `mj_getState` per creature) on
  the world's threads and scratch data, never touching the world's state. So both do
  the same MuJoCo work, and alternating in the same run means both see the same
  machine load; which comes first alternates block by block.
* `frame_ms`: a whole framework frame. `raw_mujoco_ms`: a bare frame.
  `overhead_ratio` = frame_ms / raw_mujoco_ms (the design's target is <= 1.10).
* `systems`: each system's `process`, wrapped with `timed`; `physics_ms` is the
  physics layer's share: the `physics` system (controls and sucker switches in,
  stepping) plus `physics_sync` (poses out).
* `realtime_factor`: simulated seconds per wall second of framework frames.
* `rss_mb`: the process's resident memory at the end (psutil).
* `lod`: whether level of detail was on; `tiers`: creatures per physics tier at the
  end (`world.lod.counts()`); `promotions` / `demotions`: tier changes over the run.
  The bare frames step each creature at the tier the framework steps it at (KINEMATIC
  ones not at all): they step the framework's own inputs.

With `progress`, tqdm bars on stderr (when it is a terminal) show the build, the
warm-up and the timed frames.
"""

from __future__ import annotations

import copy
import math
import os
import statistics
import sys
import time
from collections import defaultdict
from collections.abc import Callable
from typing import NoReturn, ParamSpec, TypedDict, TypeVar

import psutil
from tqdm import tqdm

from ecs_tentacles.options import WorldOptions
from ecs_tentacles.physics import heap
from ecs_tentacles.physics.bare import BareFrame, FrameCapture
from ecs_tentacles.world import World

BLOCK = 10  # frames per interleaved block
WARMUP = 30  # untimed frames first: goals chosen, suckers in use, kernels loaded
PHYSICS_SYSTEMS = ("physics", "physics_health", "physics_sync")


P = ParamSpec("P")
R = TypeVar("R")


class Timings(TypedDict):
    """`measure`'s figures: medians over the timed blocks, in ms a frame."""

    frames: int
    frame_ms: float
    physics_ms: float
    raw_mujoco_ms: float
    overhead_ratio: float  # frame_ms / raw_mujoco_ms
    realtime_factor: float
    systems: dict[str, float]  # each system's


class Sizes(TypedDict):
    """What `bench` built: creatures, bodies, stepping threads, seconds to build."""

    creatures: int
    bodies: int
    threads: int
    build_s: float


class Ends(TypedDict):
    """The world as `bench` left it: asleep, models compiled, recoveries, tiers."""

    asleep: int
    compiles: int
    recoveries: int
    lod: bool
    tiers: dict[str, int]
    promotions: int
    demotions: int


class BenchResult(Sizes, Timings, Ends):
    """`bench`'s report (its keys in the order `bench`'s docstring gives)."""

    rss_mb: float


def timed(func: Callable[P, R], bucket: list[float]) -> Callable[P, R]:
    """`func` wrapped so every call adds its wall seconds to `bucket[0]`."""

    def wrapper(*args: P.args, **kwargs: P.kwargs) -> R:
        start = time.perf_counter()
        result = func(*args, **kwargs)
        bucket[0] += time.perf_counter() - start
        return result

    return wrapper


def time_systems(world: World) -> dict[str, list[float]]:
    """Wrap every scheduled system's `process` with `timed`; return the buckets by name."""
    buckets: dict[str, list[float]] = {s.name: [0.0] for s in world.schedule}
    for system in world.schedule:
        system.process = timed(system.process, buckets[system.name])  # type: ignore[method-assign]
    return buckets


def _bare_block(world: World, frames: list[BareFrame], k: int) -> float:
    """Seconds to step the first `k` of `frames` with MuJoCo alone."""
    physics, substeps = world.physics, world.settings.substeps
    start = time.perf_counter()
    for frame in frames[:k]:
        physics.step_bare(frame, substeps)
    return time.perf_counter() - start


def _framework_block(
    world: World, frames: int, buckets: dict[str, list[float]], capture: FrameCapture
) -> float:
    """Seconds to run `frames` framework frames, less the capture (captured into
    `capture`); `buckets` hold each system's seconds, the physics' less the capture."""
    for bucket in buckets.values():
        bucket[0] = 0.0
    capture.frames, capture.seconds = [], 0.0
    start = time.perf_counter()
    world.step(frames)
    took = time.perf_counter() - start
    if "physics" in buckets:
        buckets["physics"][0] -= capture.seconds
    return took - capture.seconds


def _bar(total: int, desc: str, progress: bool, **kwargs: object) -> tqdm[NoReturn]:
    """A frame bar on stderr, shown only with `progress` and a terminal there."""
    disable = None if progress else True
    return tqdm(
        total=total,
        unit="frame",
        desc=desc,
        disable=disable,
        file=sys.stderr,
        leave=False,
        **kwargs,
    )


def measure(
    world: World, frames: int, *, block: int = BLOCK, warmup: int = WARMUP, progress: bool = False
) -> Timings:
    """Median ms per frame of `frames` framework frames and as many bare ones, interleaved."""
    if frames < 1 or block < 1 or warmup < 0:
        raise ValueError(f"frames and block must be >= 1, warmup >= 0; got {frames, block, warmup}")
    capture = FrameCapture(world.physics)
    try:
        with _bar(warmup, "bench warm-up", progress) as bar:
            for _ in range(warmup):
                capture.frames = []  # the last warm-up frame is kept
                world.step(1)
                bar.update(1)
        _bare_block(world, capture.frames, 1)  # the bare path's first call warms it up
        buckets = time_systems(world)
        per_frame: dict[str, list[float]] = defaultdict(list)
        with _bar(frames, "bench frames", progress) as bar:
            for index, first in enumerate(range(0, frames, block)):
                k = min(block, frames - first)
                _timed_block(world, k, buckets, capture, per_frame, bare_first=index % 2 == 1)
                bar.update(k)
    finally:
        capture.close()
        capture.frames = []
        heap.trim()  # the captures' memory goes back: `rss_mb` is the world's
    physics = zip(*(per_frame[name] for name in PHYSICS_SYSTEMS), strict=True)
    physics_ms = statistics.median(map(sum, physics))
    medians = {name: statistics.median(values) for name, values in per_frame.items()}
    frame_ms, raw_ms = medians.pop("frame"), medians.pop("raw")
    return {
        "frames": frames,
        "frame_ms": frame_ms,
        "physics_ms": physics_ms,
        "raw_mujoco_ms": raw_ms,
        "overhead_ratio": frame_ms / raw_ms if raw_ms > 0 else math.inf,
        "realtime_factor": 1000 * world.settings.dt / frame_ms,
        "systems": medians,
    }


def _timed_block(
    world: World,
    k: int,
    buckets: dict[str, list[float]],
    capture: FrameCapture,
    per_frame: dict[str, list[float]],
    *,
    bare_first: bool,
) -> None:
    """One block of `k` framework frames and `k` bare ones, in that order or the other
    (bare first steps the frames the last block captured); appends each figure's ms per
    frame to `per_frame`."""
    bare = _bare_block(world, capture.frames, k) if bare_first else 0.0
    per_frame["frame"].append(_framework_block(world, k, buckets, capture) * 1000 / k)
    for name, bucket in buckets.items():
        per_frame[name].append(bucket[0] * 1000 / k)
    if not bare_first:
        bare = _bare_block(world, capture.frames, k)
    per_frame["raw"].append(bare * 1000 / k)


def bench(
    source: str | os.PathLike[str] | dict[str, object],
    options: WorldOptions | None = None,
    *,
    frames: int = 120,
    block: int = BLOCK,
    warmup: int = WARMUP,
    sleep: bool = True,
    progress: bool = False,
) -> BenchResult:
    """Build `source` (scene path, bundled name or dict), run `measure`, report sizes.

    The keys, in order: creatures, bodies, threads, build_s, frames, frame_ms,
    physics_ms, raw_mujoco_ms, overhead_ratio, realtime_factor, systems, rss_mb, then
    asleep (creatures asleep at the end), compiles (models compiled: one per
    morphology, shared by its creatures), recoveries, lod, tiers, promotions, demotions.
    With `sleep=False` idle creatures are stepped like the rest (to show what sleep saves).
    `options` build the world (`ecs_tentacles.options.WorldOptions`: threads, level of
    detail over the scene's and a `focus` region whose creatures always run full).
    """
    if not sleep:
        source = _without_sleep(source)
    start = time.perf_counter()
    with _bar(1, "bench: building the world", progress, bar_format="{desc} ..."):
        world = World.from_scene(source, options)
    build_s = time.perf_counter() - start
    try:
        sizes: Sizes = {
            "creatures": len(world.physics),
            "bodies": world.physics.bodies,  # creature bodies, contact proxies not counted
            "threads": int(world.physics.threads),
            "build_s": build_s,
        }
        timings = measure(world, frames, block=block, warmup=warmup, progress=progress)
        level = world.lod
        after: Ends = {
            "asleep": world.physics.sleep.asleep,
            "compiles": world.physics.compiles,
            "recoveries": world.physics.health.recoveries,
            "lod": bool(level.enabled),
            "tiers": level.counts(),
            "promotions": level.promotions,
            "demotions": level.demotions,
        }
    finally:
        world.close()
    rss_mb = psutil.Process().memory_info().rss / 2**20
    return {**sizes, **timings, "rss_mb": rss_mb, **after}


def _without_sleep(source: str | os.PathLike[str] | dict[str, object]) -> dict[str, object]:
    from ecs_tentacles.scene.load import load_scene

    scene = copy.deepcopy(load_scene(source))
    scene["physics"]["sleep"] = False
    return scene
