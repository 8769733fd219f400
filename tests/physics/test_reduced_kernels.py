"""The reduced tier's map kernel gives numpy's numbers bit for bit, at the edges too."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from ecs_tentacles.physics import reduced as reduced_module
from ecs_tentacles.physics.reduced import ReducedModel
from ecs_tentacles.physics.tiers import REDUCED
from ecs_tentacles.world import World

SCENE = {
    "version": 1,
    "creatures": [{"name": "c", "position": [0.0, 0.0], "tentacles": {"count": 3, "links": 6}}],
}


@pytest.fixture
def reduced(make_world: Callable[..., World]) -> ReducedModel:
    world = make_world(SCENE)
    batch = world.physics.batches[0]
    batch.prepare(REDUCED, 1)
    assert batch.reduced is not None
    return batch.reduced


def _states(width: int, rows: int, seed: int, limit: float) -> np.ndarray:
    """`rows` states of `width` entries: ordinary values, values past the joints' limits
    both ways, and the edges (NaN, infinities, signed zeros, the limit itself and one ulp
    beside it)."""
    rng = np.random.default_rng(seed)
    states = rng.normal(0.0, 0.5, (rows, width))
    states[:, 1::3] *= 40.0  # far past any limit: clipped
    beside = [np.nextafter(limit, np.inf), np.nextafter(-limit, -np.inf)]
    edges = np.array([np.nan, np.inf, -np.inf, -0.0, 0.0, limit, -limit, *beside, 1e-300])
    for row in range(rows):
        at = rng.choice(width, size=min(width, len(edges)), replace=False)
        states[row, at] = edges[: len(at)]
    return states


@pytest.mark.parametrize("rows", [0, 1, 7])
def test_the_maps_are_numpys_bit_for_bit(
    reduced: ReducedModel, monkeypatch: pytest.MonkeyPatch, rows: int
) -> None:
    assert reduced_module.KERNELS.get() is not None  # numba comes with the dev extra
    full_width = max(s.stop for s in reduced.full_slices.values())
    limit = float(reduced.limit[0])
    results = []
    for backend in ("auto", "numpy"):
        monkeypatch.setattr(reduced_module.KERNELS, "backend", backend)
        full = _states(full_width, rows, 1, limit)
        pulled = np.full((rows, reduced.size), -7.0)
        reduced.pull_rows(full, pulled)
        small = _states(reduced.size, rows, 2, limit)
        shown = np.full((rows, full_width), -7.0)
        reduced.expand_rows(small, shown)
        one = np.full(full_width, -7.0)
        if rows:
            reduced.expand_state(small[0], one)
        results.append((pulled, shown, one))
    for kernel, numpy in zip(*results, strict=True):
        assert kernel.tobytes() == numpy.tobytes()  # bits: NaN and -0.0 included
    pulled, shown, _ = results[0]
    if rows:
        assert not (pulled == -7.0).all() and np.isnan(shown).any()  # edges reached the maps
        angles = shown[:, reduced._angles[1]]
        finite = angles[np.isfinite(angles)]
        assert (np.abs(finite) <= reduced.limit.max()).all()  # clipped into the limits
        assert (np.abs(finite) == reduced.limit.max()).any()
