"""The reduced tier stepped by MuJoCo's own batch (`mujoco.batch.Batch`) against the
framework's bare loop: how fast, and whether to the bit.

    python tools/bench_batch_step.py                      # 1,024 uniform, 2 threads
    python tools/bench_batch_step.py --crowd 10000 --frames 15 --json

A crowd is built and stepped `--warmup` frames; the next `--frames` frames' stepping
inputs are captured (`physics.bare.FrameCapture`: each REDUCED row's state, servos,
sucker anchors, proxy sizes, applied forces). Each captured frame's REDUCED rows are
then stepped two ways, interleaved, `--repeat` times each:

- loop: the framework's bare frame (`PhysicsBackend.step_bare`: per row on the
  backend's threads, the overlay into a scratch model, `mj_setState`, `mj_step`,
  `mj_getState`), what `bench` reports as bare MuJoCo;
- batch: one `mujoco.batch.Batch` of the reduced model on as many threads, each row a
  simulation whose overlay fields are its own (`Batch.expand`: actuator gains, biases
  and torque limits, equality anchors, proxy sizes and bounds, the timestep of its
  split), stepped in one call per split.

Filling the batch (states in, expanded fields) is not timed: it is what a port would
write in place. Reported: each way's median milliseconds a frame (and spread), their
ratio, and how many rows ended bit for bit where the loop's did.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from typing import Any

import mujoco
import numpy as np

from ecs_tentacles.creator.crowd import crowd_scene
from ecs_tentacles.options import WorldOptions
from ecs_tentacles.physics.bare import BareFrame, CapturedRows, FrameCapture
from ecs_tentacles.physics.state_layout import STATE
from ecs_tentacles.physics.tiers import REDUCED, reduced_substeps
from ecs_tentacles.world import World

OVERLAY = ("actuator_gainprm", "actuator_biasprm", "actuator_forcerange", "eq_data",
           "geom_size", "geom_rbound", "geom_aabb")  # fmt: skip
WHOLE = mujoco.mjtState.mjSTATE_INTEGRATION  # a batch's state rows


def _positive(text: str) -> int:
    value = int(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be >= 1, got {value}")
    return value


def parse(argv: list[str] | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--crowd", type=_positive, default=1024, help="creatures (uniform)")
    parser.add_argument("--threads", type=_positive, default=2)
    parser.add_argument("--warmup", type=_positive, default=90, help="frames before capturing")
    parser.add_argument("--frames", type=_positive, default=9, help="frames captured")
    parser.add_argument("--repeat", type=_positive, default=3, help="timed runs of each way")
    parser.add_argument("--json", action="store_true", help="one JSON object on stdout")
    return parser.parse_args(argv)


class Unavailable(Exception):
    """Nothing to compare: the crowd fit the full budget, or MuJoCo has no batch."""


class BatchStep:
    """A batch of `captured`'s rows on the reduced model of `world`'s first batch."""

    def __init__(self, world: World, captured: CapturedRows, threads: int):
        batch = world.physics.batches[0]
        reduced = batch.reduced
        assert reduced is not None
        self.model, self.reduced = reduced.model, reduced
        self.captured = captured
        count = len(captured.rows)
        self.batch = _batch_module().Batch(self.model, nsim=count, nthread=threads)
        self.data = mujoco.MjData(self.model)
        fields = {name: self.batch.expand(name) for name in (*OVERLAY, "opt.timestep")}
        m = batch.scratch_for(0, REDUCED).model
        servos = reduced.servos(captured.kp, captured.kv, captured.torque)
        write = reduced.overlay_writer(captured, m, servos)
        self.split = np.zeros(count, dtype=np.int64)
        d, rows = self.data, self.batch.state
        assert rows.shape[1] == mujoco.mj_stateSize(self.model, WHOLE)
        for position in range(count):
            self.split[position] = write(position, position)
            for name in OVERLAY:
                fields[name][position] = getattr(m, name)
            fields["opt.timestep"][position] = m.opt.timestep
            mujoco.mj_resetData(self.model, d)
            mujoco.mj_setState(self.model, d, captured.states[position], STATE)
            d.xfrc_applied[:] = captured.forces.get(position, 0.0)
            mujoco.mj_getState(self.model, d, rows[position], WHOLE)
        self._start = rows.copy()

    def load(self) -> None:
        """Every simulation back at its captured state."""
        self.batch.state[:] = self._start

    def step(self, substeps: int) -> None:
        """Every row `substeps` steps of its split, one call per split."""
        for split in np.unique(self.split).tolist():
            ids = np.flatnonzero(self.split == split)
            self.batch.step(ids, nstep=substeps * split)

    def states(self) -> np.ndarray:
        """Each simulation's state in the framework's layout (`STATE`)."""
        d, m = self.data, self.model
        out = np.zeros_like(self.captured.states)
        for position in range(len(out)):
            mujoco.mj_setState(m, d, self.batch.state[position], WHOLE)
            mujoco.mj_getState(m, d, out[position], STATE)
        return out


def _batch_module() -> Any:
    """`mujoco.batch` (MuJoCo 4.0 and later), or `Unavailable`."""
    try:
        import mujoco.batch
    except ImportError as exc:
        raise Unavailable(
            f"needs mujoco.batch (MuJoCo 4.0 or later), have {mujoco.__version__}"
        ) from exc
    return mujoco.batch


def reduced_only(frame: BareFrame) -> BareFrame:
    """`frame` with its REDUCED rows only (what both ways step)."""
    rows = [{REDUCED: tiers[REDUCED]} if REDUCED in tiers else {} for tiers in frame.rows]
    active = frame.active & (frame.tier == REDUCED)
    return BareFrame(active, frame.tier, rows)


def measure(args: argparse.Namespace) -> dict[str, Any]:
    scene = crowd_scene(args.crowd, seed=0, uniform=True)
    world = World.from_scene(scene, WorldOptions(threads=args.threads))
    world.step(args.warmup)
    capture = FrameCapture(world.physics, keep=True)
    world.step(args.frames)
    capture.close()
    physics, substeps = world.physics, world.settings.substeps
    steps = reduced_substeps(substeps)
    frames = [reduced_only(frame) for frame in capture.frames]
    frames = [f for f in frames if f.rows and REDUCED in f.rows[0]]
    if not frames:
        raise Unavailable(f"no creature of {args.crowd} was stepped REDUCED: try a larger --crowd")
    batches = [BatchStep(world, f.rows[0][REDUCED], args.threads) for f in frames]
    loop_ms: list[float] = []
    batch_ms: list[float] = []
    for _ in range(args.repeat):  # interleaved: the loop's frames, then the batch's
        began = time.perf_counter()
        for frame in frames:
            physics.step_bare(frame, substeps)
        loop_ms.append((time.perf_counter() - began) * 1e3 / len(frames))
        spent = 0.0
        for step in batches:
            step.load()
            began = time.perf_counter()
            step.step(steps)
            spent += time.perf_counter() - began
        batch_ms.append(spent * 1e3 / len(frames))
    rows = same = 0
    for frame, step in zip(frames, batches, strict=True):
        after = frame.rows[0][REDUCED].after
        assert after is not None
        mine = step.states()
        rows += len(mine)
        same += int(sum(np.array_equal(a, b) for a, b in zip(after, mine, strict=True)))
    loop, batch = statistics.median(loop_ms), statistics.median(batch_ms)
    return {
        "creatures": args.crowd,
        "threads": args.threads,
        "frames": len(frames),
        "reduced_rows": rows // len(frames),
        "loop_ms": loop,
        "loop_spread_ms": [min(loop_ms), max(loop_ms)],
        "batch_ms": batch,
        "batch_spread_ms": [min(batch_ms), max(batch_ms)],
        "batch_over_loop": batch / loop,
        "rows_bit_identical": same,
        "rows_compared": rows,
    }


def main(argv: list[str] | None = None) -> int:
    args = parse(argv)
    try:
        result = measure(args)
    except Unavailable as exc:
        print(f"bench_batch_step: {exc}", file=sys.stderr)
        return 1
    if args.json:
        print(json.dumps(result))
    else:
        print(
            f"{result['creatures']} creatures, {result['reduced_rows']} reduced a frame,"
            f" {result['threads']} threads, {result['frames']} frames:"
            f" loop {result['loop_ms']:.2f} ms, batch {result['batch_ms']:.2f} ms"
            f" ({result['batch_over_loop']:.2f}x);"
            f" {result['rows_bit_identical']} of {result['rows_compared']} rows bit-identical"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
