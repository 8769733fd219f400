"""A frame's control values and table: the kernel gives numpy's bits."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_array_equal

from ecs_tentacles.fur import rig
from ecs_tentacles.fur.bind import control_kernels, control_plan
from ecs_tentacles.fur.rig import Plan
from ecs_tentacles.fur.stores import FurData
from ecs_tentacles.world import World

CROWD = Path(__file__).parents[1] / "data" / "crowd16.json"  # 16 creatures, a dozen furred
FIELDS = ("lift", "aim", "direction", "twist", "position", "offset")


def _both(fur: FurData, monkeypatch: pytest.MonkeyPatch) -> list[tuple[Plan, np.ndarray]]:
    plans = []
    for backend in ("auto", "numpy"):
        monkeypatch.setattr(rig, "BACKEND", backend)
        plans.append(control_plan(fur))
    return plans


def _same_bits(a: np.ndarray, b: np.ndarray) -> None:
    """Equal to the bit (-0.0 is not 0.0; NaN is NaN)."""
    assert a.dtype == b.dtype == np.float32 and a.shape == b.shape
    assert_array_equal(a.view(np.uint32), b.view(np.uint32))


def test_the_kernel_gives_numpys_bits_at_the_edges(
    make_world: Callable[..., World], monkeypatch: pytest.MonkeyPatch
) -> None:
    assert control_kernels() is not None  # numba comes with the dev extra
    world = make_world(str(CROWD))
    world.step(2)
    fur = world.resource(FurData)
    c, sets = fur.controls, fur.sets
    n = len(c)
    assert n >= 8
    rng = np.random.default_rng(2)
    edges = np.array([-0.3, 1.7, np.nan, -0.0, 0.0, 1.0, 0.25, np.inf])
    for name in ("lift", "aim", "direction", "random", "dynamic"):
        getattr(c, name)[:] = rng.permutation(np.resize(edges, n))
    c.drive_lift[:] = rng.uniform(-0.2, 0.4, n)
    c.drive_random[:] = rng.uniform(0.0, 0.3, n)
    c.position += rng.normal(0.0, 0.01, c.position.shape)
    sets.enabled[0, 1] = 0.0  # a fur without aim
    kernel, numpy = _both(fur, monkeypatch)
    for name in FIELDS:
        _same_bits(getattr(kernel[0].values, name), getattr(numpy[0].values, name))
    _same_bits(kernel[0].table, numpy[0].table)
    _same_bits(kernel[1], numpy[1])
    flags = ("lifting", "aiming", "directing", "twisting")
    assert [getattr(kernel[0], f) for f in flags] == [getattr(numpy[0], f) for f in flags]
    assert not np.signbit(kernel[0].values.aim).any()  # -0.0 clipped to 0.0, on any CPU


def test_behaviours_nobody_uses_are_skipped_alike(
    make_world: Callable[..., World], monkeypatch: pytest.MonkeyPatch
) -> None:
    world = make_world("hedgehog_octopus")
    fur = world.resource(FurData)
    c = fur.controls
    c.lift[:] = c.drive_lift[:] = 0.0
    c.aim[:] = -0.0  # clipped to 0.0: nothing to do
    c.random[:] = c.drive_random[:] = 0.0
    c.direction[:] = 0.5
    kernel, numpy = _both(fur, monkeypatch)
    for plan in (kernel[0], numpy[0]):
        assert (plan.lifting, plan.aiming, plan.directing, plan.twisting) == (
            False,
            False,
            True,
            False,
        )
    _same_bits(kernel[0].table, numpy[0].table)
