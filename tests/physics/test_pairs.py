"""near_pairs and NearPairCache: the cache answers exactly what near_pairs would."""

from __future__ import annotations

import functools
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
from numpy.testing import assert_array_equal

from ecs_tentacles.physics.pairs import DENSE_PAIRS, NearPairCache, near_pairs, spheres_within


def _crowd(rng: np.random.Generator, n: int) -> tuple[np.ndarray, np.ndarray]:
    side = np.sqrt(n) * 1.2  # about one creature per 1.4 square metres: many neighbours
    centre = np.column_stack([rng.uniform(0, side, (n, 2)), np.full(n, 0.1)])
    return centre, rng.uniform(0.2, 0.6, n)


def test_the_cache_gives_near_pairs_answers_as_creatures_wander() -> None:
    rng = np.random.default_rng(3)
    n = max(2 * DENSE_PAIRS, 300)  # large enough for the tree
    centre, radius = _crowd(rng, n)
    cache = NearPairCache(slack=0.2)
    calls = 0
    for frame in range(120):
        centre[:, :2] += rng.normal(0.0, 0.01, (n, 2))  # a crawl: ~1 cm a frame
        radius = np.clip(radius + rng.normal(0.0, 0.005, n), 0.1, 0.7)  # tentacles reach
        if frame == 60:
            centre[7, :2] += 3.0  # one creature thrown far: the kept pairs are stale
        for margin in (0.05, 0.2):  # the proxies' margin, the level of detail's
            got = cache(centre, radius, margin)
            want = near_pairs(centre, radius, margin)
            calls += 1
            assert_array_equal(got[0], want[0])
            assert_array_equal(got[1], want[1])
            assert len(want[0]) > 0
    assert 2 <= cache.queries < calls // 4  # the tree asked again now and then, not each call


def test_the_cache_asks_again_when_the_crowd_changes_size() -> None:
    rng = np.random.default_rng(4)
    centre, radius = _crowd(rng, 300)
    cache = NearPairCache()
    cache(centre, radius, 0.1)
    fewer = cache(centre[:-1], radius[:-1], 0.1)
    want = near_pairs(centre[:-1], radius[:-1], 0.1)
    assert_array_equal(fewer[0], want[0])
    assert cache.queries == 2


def test_small_crowds_and_bad_slack() -> None:
    rng = np.random.default_rng(5)
    centre, radius = _crowd(rng, 20)
    cache = NearPairCache()
    assert_array_equal(cache(centre, radius, 0.1)[0], near_pairs(centre, radius, 0.1)[0])
    assert cache.queries == 0  # the dense comparison: nothing kept
    with pytest.raises(ValueError, match="slack"):
        NearPairCache(slack=0.0)


def _by_backend(monkeypatch: pytest.MonkeyPatch, call: Callable[[], Any]) -> list[Any]:
    """`call()` with the kernels, then with numpy: [kernel's answer, numpy's]."""
    from ecs_tentacles.physics import pairs as module

    found = []
    for backend in ("auto", "numpy"):
        monkeypatch.setattr(module.KERNELS, "backend", backend)
        if backend == "auto":
            assert module.KERNELS.get() is not None  # numba comes with the dev extra
        found.append(call())
    return found


@pytest.mark.parametrize("dimensions", [2, 3])
def test_the_sphere_test_kernel_gives_the_numpy_answers(
    dimensions: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    rng = np.random.default_rng(7)
    centre, radius = _crowd(rng, 600)
    centre = centre[:, :dimensions]
    a, b = rng.integers(0, 600, 5000), rng.integers(0, 600, 5000)
    found = _by_backend(monkeypatch, lambda: spheres_within(centre, radius, a, b, 0.3))
    assert_array_equal(found[0], found[1])
    assert 0 < found[0].sum() < len(a)


@pytest.mark.parametrize("dimensions", [2, 3])
def test_a_small_crowds_pairs_are_the_same_with_the_kernel_and_numpy(
    dimensions: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    rng = np.random.default_rng(11)
    for n in (0, 1, 2, 16, DENSE_PAIRS):
        centre, radius = _crowd(rng, n)
        centre = centre[:, :dimensions]
        if n > 2:  # two spheres exactly `margin` apart (not near) and one NaN (never near)
            radius[1] = np.linalg.norm(centre[1] - centre[0]) - radius[0] - 0.3
            centre[2] = np.nan
        found = _by_backend(monkeypatch, functools.partial(near_pairs, centre, radius, 0.3))
        for kernel, numpy in zip(found[0], found[1], strict=True):
            assert kernel.dtype == numpy.dtype
            assert_array_equal(kernel, numpy)
        if n >= 16:
            assert 0 < len(found[0][0]) < n * (n - 1)


@pytest.mark.parametrize("n", [DENSE_PAIRS - 4, 400])
def test_the_pairs_of_some_creatures_are_theirs_of_all_the_pairs_in_order(n: int) -> None:
    """The proxies ask for the pairs of the stepped creatures only (a few of a replayed
    crowd): what filtering every pair would give, in the same order."""
    rng = np.random.default_rng(6)
    centre, radius = _crowd(rng, n)
    cache, found = NearPairCache(slack=0.2), 0
    for frame in range(30):
        centre[:, :2] += rng.normal(0.0, 0.01, (n, 2))
        among = rng.random(n) < 0.2
        among[0] = frame % 2 == 0  # a first creature with pairs, or not
        a, b = near_pairs(centre, radius, 0.05)
        got = cache(centre, radius, 0.05, among=among)
        found += len(got[0])
        assert_array_equal(got[0], a[among[a]])
        assert_array_equal(got[1], b[among[a]])
        everyone = cache(centre, radius, 0.05, among=np.ones(n, dtype=bool))
        assert_array_equal(everyone[0], a)
        assert_array_equal(everyone[1], b)
    assert found > 30


def test_the_kept_pairs_are_filtered_to_the_same_pairs_by_the_kernel_and_numpy(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The cache's answer from its kept pairs (some creatures' or everyone's) is the
    same pairs in the same order by either path."""
    rng = np.random.default_rng(12)
    n = 400
    centre, radius = _crowd(rng, n)
    cache = NearPairCache(slack=0.2)
    cache(centre, radius, 0.05)  # the kept pairs, asked of the tree once
    for _ in range(12):
        centre[:, :2] += rng.normal(0.0, 0.005, (n, 2))
        among = rng.random(n) < 0.3
        for which in (among, None):
            found = _by_backend(monkeypatch, lambda w=which: cache(centre, radius, 0.05, w))
            for kernel, numpy in zip(found[0], found[1], strict=True):
                assert kernel.dtype == numpy.dtype
                assert_array_equal(kernel, numpy)
            assert len(found[0][0]) > 0
    assert cache.queries == 1  # every answer came from the kept pairs


def test_a_nan_sphere_makes_the_cache_ask_the_tree_again() -> None:
    rng = np.random.default_rng(7)
    centre, radius = _crowd(rng, 300)
    cache = NearPairCache()
    cache(centre, radius, 0.1)
    cache(centre, radius, 0.1)
    assert cache.queries == 1
    radius = radius.copy()
    radius[5] = np.nan  # a blown-up creature's reach: never trusted
    cache(centre, radius, 0.1)
    assert cache.queries == 2
