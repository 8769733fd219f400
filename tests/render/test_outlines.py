"""Outlined ribbons: each segment an instance twice, the dark edge before the bright
core, and drawn as wide as they say (in pixels) wherever they are."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from ecs_tentacles.render.outlines import (
    LINE_PIXELS,
    OUTLINE,
    OUTLINE_PIXELS,
    ribbon_instances,
)


def test_edges_come_first_and_dull_cores_are_lifted() -> None:
    segments = np.array(
        [[0, 0, 0, 0.2, 0.2, 0.2, 1], [1, 0, 0, 0.2, 0.2, 0.2, 1],
         [0, 1, 0, 1.0, 1.0, 1.0, 1], [0, 2, 0, 1.0, 1.0, 1.0, 1]], float,
    )  # fmt: skip
    rows = ribbon_instances(segments)
    assert rows.shape == (4, 11) and rows.dtype == np.float32
    np.testing.assert_array_equal(rows[:2, 6:10], np.float32([OUTLINE, OUTLINE]))
    np.testing.assert_array_equal(rows[:, 10], np.float32([OUTLINE_PIXELS] * 2 + [LINE_PIXELS] * 2))
    np.testing.assert_array_equal(rows[[0, 2], 0:6], np.float32([[0, 0, 0, 1, 0, 0]] * 2))
    assert rows[2, 6] > 0.2 and rows[3, 6] == 1.0  # dull lifted toward white, white stays
    assert ribbon_instances(np.zeros((0, 7))).shape == (0, 11)


def test_a_ring_is_drawn_as_wide_as_its_pixels_near_and_far(
    make_sandbox: Callable[..., Any],
) -> None:
    """A line across the picture, seen from 5 m and from 20 m: its dark edge about
    OUTLINE_PIXELS wide either way, its bright core about LINE_PIXELS inside it."""
    widths = []
    for distance in (5.0, 20.0):
        sandbox = make_sandbox("thesis_four_by_six", hud=False)
        renderer = sandbox.renderer
        renderer.clean = True
        renderer.camera.look_from(np.array([0.0, -distance, distance]), np.zeros(3))
        centre = np.array([0.0, 0.0, 0.05])
        line = np.array(
            [[*(centre - [2, 0, 0]), 1, 0.2, 0.2, 1], [*(centre + [2, 0, 0]), 1, 0.2, 0.2, 1]]
        )
        renderer.extra_lines.append(lambda world, line=line: line)
        renderer.draw(1.0)
        picture = renderer.target.read().astype(int)
        column = picture[:, picture.shape[1] // 2]
        dark = np.flatnonzero(column.sum(axis=1) < 90)
        red = np.flatnonzero((column[:, 0] > 180) & (column[:, 1] < 170))
        widths.append((len(dark) + len(red), len(red)))
    for whole, core in widths:
        assert abs(whole - OUTLINE_PIXELS) <= 1.5 and abs(core - LINE_PIXELS) <= 1.5
