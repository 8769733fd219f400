"""The dynamic blend's strand step: numba's kernel (serial or parallel) equals numpy's."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from ecs_tentacles.fur import rig
from ecs_tentacles.fur.dynamics import Strands, blend_profile

POINTS, N = 6, 1100


def strands(guides: np.ndarray, rng: np.random.Generator) -> Strands:
    m = len(guides)
    segment = np.full((POINTS, m), 0.01, dtype=np.float32)
    segment[0] = 0.0
    return Strands(
        guides=guides,
        segment=segment,
        pull=rng.uniform(0.02, 0.3, m).astype(np.float32),
        keep=rng.uniform(0.8, 0.99, m).astype(np.float32),
        gravity=np.tile(np.float32([[0.0], [0.0], [-9.81 / 3600]]), (1, m)),
        profile=blend_profile(POINTS)[:, None, None],
    )


def frame(rng: np.random.Generator, t: int) -> tuple[np.ndarray, np.ndarray]:
    """Rig curves (N, points, 3) growing along +z from roots that move, and frames."""
    roots = rng.normal(size=(N, 3)).astype(np.float32) * 0.01 + [0.002 * t, 0.0, 0.0]
    steps = np.arange(POINTS, dtype=np.float32)[:, None] * np.float32([0.003, 0.0, 0.0095])
    curves = (roots[:, None] + steps[None]).astype(np.float32)
    frames = np.zeros((N, 4, 3), np.float32)
    frames[:, 3] = roots
    return curves, frames


def test_strand_kernel_equals_numpy() -> None:
    pytest.importorskip("numba")
    rng = np.random.default_rng(5)
    guides = np.sort(rng.choice(N, 700, replace=False))  # some guides are not dynamic
    numpy_s, serial_s, parallel_s = (strands(guides, np.random.default_rng(1)) for _ in "abc")
    normal = np.tile(np.float32([[0.0], [0.3], [0.954]]), (1, len(guides)))
    weight = np.random.default_rng(2).uniform(0, 1, len(guides)).astype(np.float32)
    for t in range(12):
        curves, frames = frame(rng, t)
        rigged = np.ascontiguousarray(curves[guides].transpose(1, 2, 0))
        expected = curves.copy()
        expected[guides] = numpy_s.step(rigged, frames[guides, 3].T, normal, weight).transpose(
            2, 0, 1
        )
        serial, parallel = curves.copy(), curves.copy()
        assert serial_s.step_kernel(serial, frames, normal, weight, parallel=False)
        assert parallel_s.step_kernel(parallel, frames, normal, weight, parallel=True)
        assert_array_equal(serial, parallel)
        assert_allclose(serial, expected, atol=1e-7)
        assert_array_equal(np.delete(serial, guides, axis=0), np.delete(curves, guides, axis=0))
    assert np.abs(serial - curves).max() > 1e-3  # the strands did lag behind the rig


def test_without_numba_the_kernel_step_declines(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(rig, "BACKEND", "numpy")
    s = strands(np.arange(3), np.random.default_rng(0))
    curves, frames = np.zeros((3, POINTS, 3), np.float32), np.zeros((3, 4, 3), np.float32)
    assert not s.step_kernel(curves, frames, np.zeros((3, 3), np.float32), np.ones(3, np.float32))
    assert s.pos is None  # nothing stepped
