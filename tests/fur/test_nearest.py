"""The nearest guide roots (`fur.nearest`): exactly what comparing every point with every
root finds, nearest first, ties to the lower index, in memory linear in the inputs."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_array_equal

from ecs_tentacles.fur.nearest import nearest


def _every_pair(points: np.ndarray, roots: np.ndarray, k: int) -> tuple[np.ndarray, np.ndarray]:
    """The rule by brute force: every squared distance, ranked by (distance, index)."""
    d2 = np.sum((points[:, None, :] - roots[None]) ** 2, axis=2)
    index = np.broadcast_to(np.arange(len(roots)), d2.shape)
    ranked = np.lexsort((index, d2), axis=-1)[:, :k]
    return ranked, np.take_along_axis(d2, ranked, axis=1)


def test_random_roots_give_the_brute_force_answer_bit_for_bit() -> None:
    rng = np.random.default_rng(1)
    for _ in range(60):
        roots = rng.normal(size=(int(rng.integers(1, 300)), 3))
        points = rng.normal(size=(int(rng.integers(1, 2000)), 3))
        k = min(3, len(roots))
        found, d2 = nearest(points, roots, k)
        want, want_d2 = _every_pair(points, roots, k)
        assert_array_equal(found, want)
        assert_array_equal(d2, want_d2)  # numpy's own distances: the weights do not move
        assert (np.diff(d2, axis=1) >= 0).all()  # nearest first


def test_ties_go_to_the_lower_index_with_duplicates_and_on_a_lattice() -> None:
    """Roots on a 4 x 4 x 4 lattice, many at one spot, and points on lattice points and
    half-way between: ties at every rank, each settled by the lower index."""
    rng = np.random.default_rng(2)
    lattice = np.stack(np.meshgrid(*[np.arange(4.0)] * 3), axis=-1).reshape(-1, 3)
    for _ in range(40):
        roots = lattice[rng.integers(0, len(lattice), int(rng.integers(3, 150)))]
        points = rng.integers(0, 7, size=(400, 3)) / 2.0
        found, d2 = nearest(points, roots, 3)
        want, want_d2 = _every_pair(points, roots, 3)
        assert_array_equal(found, want)
        assert_array_equal(d2, want_d2)
    twelve = np.repeat([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]], 6, axis=0)[[0, 6, 1, 7, 2, 8] * 2]
    assert_array_equal(nearest(np.array([[0.5, 0.0, 0.0]]), twelve, 3)[0], [[0, 1, 2]])


def test_fewer_roots_than_asked_are_refused() -> None:
    with pytest.raises(ValueError, match=r"k must be in \[1, 2\], got 3"):
        nearest(np.zeros((1, 3)), np.zeros((2, 3)), 3)
