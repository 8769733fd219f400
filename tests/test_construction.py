"""The thesis's construction rules (IV.A, z-up), against hand-computed numbers."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose

from ecs_tentacles.construction import link_scales, tentacle_angles, tentacle_axes, tentacle_shape

S = np.sqrt(0.5)
H = np.sqrt(3) / 2


def test_one_link_is_the_first_link_at_full_scale() -> None:
    assert_allclose(link_scales(1, 0.3), [1.0])
    shape = tentacle_shape(0.2, 0.1, 0.02, 1, 0.3)
    assert_allclose(shape.lengths, [0.1])
    assert_allclose(shape.radii, [0.02])
    assert_allclose(shape.centres, [0.25])


def test_two_links() -> None:
    shape = tentacle_shape(0.2, 0.1, 0.02, 2, 0.5)
    assert_allclose(shape.scales, [1.0, 0.5])
    assert_allclose(shape.lengths, [0.1, 0.05])
    assert_allclose(shape.radii, [0.02, 0.01])
    assert_allclose(shape.centres, [0.25, 0.325])  # 0.25 + (0.1 + 0.05) / 2


def test_ten_links() -> None:
    shape = tentacle_shape(0.2, 0.1, 0.02, 10, 0.1)
    assert_allclose(shape.scales, [1.0, 0.9, 0.8, 0.7, 0.6, 0.5, 0.4, 0.3, 0.2, 0.1], atol=1e-15)
    assert_allclose(shape.lengths, 0.1 * shape.scales, atol=1e-15)
    assert_allclose(shape.radii, 0.02 * shape.scales, atol=1e-15)
    # c1 = 0.25 + (0.1 + 0.09) / 2; c9 = 0.25 + (0.1 + 2 * (0.09 + ... + 0.02) + 0.01) / 2
    assert_allclose(shape.centres[[0, 1, 9]], [0.25, 0.345, 0.745], atol=1e-15)


def test_end_scale_one_gives_uniform_links() -> None:
    assert_allclose(link_scales(5, 1.0), np.ones(5))


@pytest.mark.parametrize(
    ("count", "expected"),
    [
        (3, [[1, 0, 0], [-0.5, H, 0], [-0.5, -H, 0]]),
        (6, [[1, 0, 0], [0.5, H, 0], [-0.5, H, 0], [-1, 0, 0], [-0.5, -H, 0], [0.5, -H, 0]]),
        (
            8,
            [
                [1, 0, 0],
                [S, S, 0],
                [0, 1, 0],
                [-S, S, 0],
                [-1, 0, 0],
                [-S, -S, 0],
                [0, -1, 0],
                [S, -S, 0],
            ],
        ),
    ],
)
def test_tentacle_axes_counter_clockwise_about_z(count: int, expected: list[list[float]]) -> None:
    assert_allclose(tentacle_axes(count), expected, atol=1e-15)
    assert_allclose(tentacle_angles(count), np.radians(360.0 * np.arange(count) / count))


@pytest.mark.parametrize(("links", "end_scale"), [(0, 0.5), (3, 0.0), (3, 1.5)])
def test_impossible_tentacles_are_refused(links: int, end_scale: float) -> None:
    with pytest.raises(ValueError):
        link_scales(links, end_scale)
