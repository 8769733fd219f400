"""Strands as ribbons: indices, vertices, and pixels that face the camera and taper."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.testing import assert_array_equal

from ecs_tentacles.fur.hooks import GuideCurves
from ecs_tentacles.fur.render.ribbons import ribbon_vertices, strip_indices
from ecs_tentacles.fur.render.strands import strands_of


def test_strip_indices_and_vertices() -> None:
    assert_array_equal(
        strip_indices(2, 3),
        [0, 1, 2, 1, 3, 2, 2, 3, 4, 3, 5, 4, 6, 7, 8, 7, 9, 8, 8, 9, 10, 9, 11, 10],
    )
    points = np.array([[[0, 0, 0], [0, 0, 1], [0, 1, 2]]], np.float32)
    curves = GuideCurves(
        points, np.array([[0.2, 0.4, 0.6, 1.0]], np.float32), np.float32([0.01]), np.zeros(1)
    )
    v = ribbon_vertices(curves).reshape(3, 2, 12)
    assert_array_equal(v[:, 0, :3], points[0])
    assert_array_equal(v[:, 1, :3], points[0])
    assert_array_equal(v[:, :, 6], [[-1, 1]] * 3)  # sides
    assert_array_equal(v[:, 0, 8], [0.0, 0.5, 1.0])  # along the strand: taper, shading
    assert_array_equal(v[1, 0, 3:6], [0, 1, 2])  # central difference tangent
    assert_array_equal(v[0, 0, 9:12], np.float32([0.2, 0.4, 0.6]))


def _width_rows(pixels: np.ndarray, background: np.ndarray) -> np.ndarray:
    """Per image row, how many pixels differ from the background."""
    return np.asarray((np.abs(pixels.astype(int) - background).sum(axis=2) > 30).sum(axis=1))


def test_ribbons_face_the_camera_and_taper(make_sandbox: Callable[..., Any]) -> None:
    from pyglet import gl

    sandbox = make_sandbox({"version": 1, "creatures": []})
    renderer = sandbox.renderer
    camera = renderer.camera
    camera.target, camera.distance, camera.pitch = np.zeros(3), 2.0, 0.0
    z = np.linspace(0.0, 1.0, 8, dtype=np.float32)
    points = np.stack([np.zeros(8), np.zeros(8), z - 0.5], axis=1)[None].astype(np.float32)
    strand = GuideCurves(
        points, np.float32([[0.9, 0.2, 0.1, 1.0]]), np.float32([0.06]), np.zeros(1)
    )
    widths = []
    for yaw in (0.0, 0.7, 1.9):
        camera.yaw = yaw
        renderer.draw()
        background = renderer.target.read()
        strands = strands_of(renderer.state)  # made here: this world has no fur
        strands.guides.update(strand)
        renderer.target.bind()
        gl.glEnable(gl.GL_DEPTH_TEST)
        calls = strands.draw(renderer.render_view)
        assert calls == 1
        changed = _width_rows(renderer.target.read(), background.astype(int))
        rows = np.flatnonzero(changed)
        assert len(rows) > 50  # the strand spans many rows
        root = changed[rows[-1] - 10]  # image rows go down: the root (z low) is at the bottom
        tip = changed[rows[0] + 10]
        assert root > tip + 3  # wide at the root, thin at the tip
        widths.append(root)
    assert max(widths) - min(widths) <= 2  # the same width from every side: it faces us
