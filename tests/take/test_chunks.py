"""Curves' points stored in steps: the error stated (at most half a step, 0.05 mm)."""

from __future__ import annotations

import numpy as np

from ecs_tentacles.take import chunks


def test_points_in_steps_come_back_within_half_a_step() -> None:
    rng = np.random.default_rng(3)
    walk = np.cumsum(rng.normal(0, 0.004, (64, 50, 16, 3)), axis=0) + rng.uniform(-90, 90, 3)
    points = walk.astype(np.float32)
    steps = chunks.quantise(points, chunks.STEP)
    assert steps.dtype == np.int64 and np.abs(steps[1:]).max() < 2**15  # small: they deflate
    back = chunks.dequantise(steps, chunks.STEP)
    float32 = np.spacing(np.float32(128.0))  # the float's own rounding at 90-odd metres
    assert np.abs(back.astype(np.float64) - points).max() <= chunks.STEP / 2 + float32
