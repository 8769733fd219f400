"""Replay's choice of the clip frame a creature starts from: the kernel is numpy's."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_array_equal

from ecs_tentacles.clips import replay


def test_the_nearest_frame_kernel_picks_numpys_frames(monkeypatch: pytest.MonkeyPatch) -> None:
    rng = np.random.default_rng(5)
    shapes = rng.normal(0.0, 0.3, (40, 21, 3))
    shapes[17] = shapes[6]  # a tie: numpy's argmin takes the first
    shapes[30] = shapes[2] + 1e-12  # all but a tie
    picked = rng.integers(0, 40, 50)
    shape = shapes[picked] + rng.normal(0.0, 0.02, (50, 21, 3))
    shape[:5] = shapes[[6, 17, 2, 30, 0]]  # exactly a frame
    shape[5:10] = rng.normal(0.0, 1.0, (5, 21, 3))  # like none of them
    assert replay.KERNELS.get() is not None  # numba comes with the dev extra
    found = []
    for backend in ("auto", "numpy"):
        monkeypatch.setattr(replay.KERNELS, "backend", backend)
        found.append(replay._nearest_frame(shapes, shape, chunk=16))
    assert_array_equal(found[0], found[1])
    assert list(found[0][:5]) == [6, 6, 2, 30, 0]
    assert (found[0][10:] == picked[10:]).mean() > 0.9  # a small nudge keeps its frame
