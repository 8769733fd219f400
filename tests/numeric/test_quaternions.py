"""quat_rotate: numba's one-pass kernel and the numpy path give the same numbers."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from ecs_tentacles.numeric import quaternions
from ecs_tentacles.numeric.quaternions import quat_about_z, quat_rotate


def _unit_quaternions(rng: np.random.Generator, n: int) -> np.ndarray:
    q = rng.normal(size=(n, 4))
    return np.asarray(q / np.linalg.norm(q, axis=1, keepdims=True))


@pytest.mark.parametrize("n", [0, 1, 17, 3000])
def test_the_kernel_rotates_bit_for_bit_as_numpy(n: int, monkeypatch: pytest.MonkeyPatch) -> None:
    assert quaternions.KERNELS.get() is not None  # numba comes with the dev extra
    rng = np.random.default_rng(n)
    q, v = _unit_quaternions(rng, n), rng.normal(scale=5.0, size=(n, 3))
    fast = quat_rotate(q, v)
    monkeypatch.setattr(quaternions.KERNELS, "backend", "numpy")
    assert_array_equal(fast, quat_rotate(q, v))
    assert fast.shape == (n, 3)


def test_rotations_keep_lengths_and_turn_about_z() -> None:
    rng = np.random.default_rng(1)
    q, v = _unit_quaternions(rng, 50), rng.normal(size=(50, 3))
    assert_allclose(np.linalg.norm(quat_rotate(q, v), axis=1), np.linalg.norm(v, axis=1))
    quarter = np.repeat(quat_about_z(np.pi / 2)[None], 3, axis=0)
    assert_allclose(quat_rotate(quarter, np.eye(3)), [[0, 1, 0], [-1, 0, 0], [0, 0, 1]], atol=1e-15)


def test_one_vector_turned_by_many_quaternions_takes_the_numpy_path() -> None:
    rng = np.random.default_rng(2)
    q = _unit_quaternions(rng, 4)
    up = quat_rotate(q, np.array([0.0, 0.0, 1.0]))  # broadcast: (4, 3)
    assert_allclose(up, quat_rotate(q, np.tile([0.0, 0.0, 1.0], (4, 1))), rtol=0, atol=0)


@pytest.mark.parametrize("n", [0, 1, 40])
def test_the_matrix_kernel_gives_numpys_rotation_matrices_bit_for_bit(
    n: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    from ecs_tentacles.fur.vectors import quat_matrices

    rng = np.random.default_rng(10 + n)
    q, v = _unit_quaternions(rng, n), rng.normal(size=(n, 3))
    fast = quat_matrices(q)
    monkeypatch.setattr(quaternions.KERNELS, "backend", "numpy")
    assert_array_equal(fast, quat_matrices(q))
    assert fast.shape == (n, 3, 3)
    assert_allclose(np.einsum("nij,nj->ni", fast, v), quat_rotate(q, v), atol=1e-12)
