"""Creature colours: one list the sandbox and the exporters share."""

from __future__ import annotations

import numpy as np

from ecs_tentacles.skin.colours import creature_colours, to_linear


def test_the_first_colours_are_distinct_warm_first_and_stable() -> None:
    colours = creature_colours(8)
    assert colours.shape == (8, 3)
    assert ((colours >= 0) & (colours <= 1)).all()
    np.testing.assert_allclose(creature_colours(3), colours[:3])  # a newcomer adds, never moves
    assert colours[0].argmax() == 0  # red first
    gaps = np.abs(colours[:, None] - colours[None, :]).max(axis=2)
    assert gaps[~np.eye(8, dtype=bool)].min() > 0.1


def test_to_linear_follows_the_srgb_curve() -> None:
    np.testing.assert_allclose(to_linear([0.0, 0.04045, 0.5, 1.0]),
                               [0.0, 0.04045 / 12.92, 0.2140, 1.0], atol=1e-4)  # fmt: skip
