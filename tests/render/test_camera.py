"""Camera maths: projection and picking agree, framing keeps points in view."""

from __future__ import annotations

import numpy as np
from numpy.testing import assert_allclose

from ecs_tentacles.render.camera import OrbitCamera, ray_sphere


def test_ground_point_inverts_projection() -> None:
    camera = OrbitCamera(800, 600, distance=4.0, shift_x=120.0)
    points = np.array([[0.3, -0.7, 0.0], [1.5, 0.2, 0.0], [-0.4, 0.9, 0.0]])
    for point, pixel in zip(points, camera.project(points), strict=True):
        hit = camera.ground_point(*pixel)
        assert hit is not None
        assert_allclose(hit, point, atol=1e-9)


def test_target_projects_to_the_shifted_centre() -> None:
    camera = OrbitCamera(800, 600, target=np.array([1.0, 2.0, 0.0]), shift_x=150.0)
    assert_allclose(camera.project(camera.target[None])[0], [400 + 150, 300], atol=1e-9)


def test_frame_keeps_every_point_on_screen() -> None:
    camera = OrbitCamera(640, 360)
    points = np.array([[-3.0, -1.0, 0.0], [4.0, 2.5, 0.3], [0.0, 6.0, 0.0]])
    camera.frame(points)
    pixels = camera.project(points)
    assert ((pixels >= 0) & (pixels <= [640, 360])).all()


def test_orbit_pan_zoom() -> None:
    camera = OrbitCamera()
    camera.orbit(0.0, 10_000.0)
    assert camera.pitch == camera.MIN_PITCH  # never under the ground
    distance = camera.distance
    camera.zoom(1)
    assert camera.distance == distance * 0.9
    before = camera.target.copy()
    camera.follow = 3
    camera.pan(100.0, 0.0)
    assert camera.follow is None and not np.allclose(camera.target, before)


def test_ray_sphere_hits_the_nearest_surface() -> None:
    hits = ray_sphere(
        np.zeros(3),
        np.array([1.0, 0.0, 0.0]),
        np.array([[5.0, 0, 0], [2.0, 0.5, 0], [-3.0, 0, 0]]),
        np.array([1.0, 0.4, 1.0]),
    )
    assert hits[0] == 4.0 and np.isinf(hits[1]) and np.isinf(hits[2])
