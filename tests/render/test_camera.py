"""Camera maths: projection and picking agree, framing keeps points in view."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose

from ecs_tentacles.render.camera import CameraChoice, OrbitCamera, parse_camera, ray_sphere


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


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("frame-all", CameraChoice("frame-all")),
        ("follow west0", CameraChoice("follow", name="west0")),
        ("follow=west0", CameraChoice("follow", name="west0")),
        ("4,-6,3,0,0,0.5", CameraChoice("fixed", eye=(4.0, -6.0, 3.0), target=(0.0, 0.0, 0.5))),
    ],
)
def test_parse_camera(text: str, expected: CameraChoice) -> None:
    assert parse_camera(text) == expected


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("frame", "must be frame-all, follow NAME or X,Y,Z,TX,TY,TZ"),
        ("follow", "follow needs a creature's name"),
        ("1,2,3", "must be frame-all, follow NAME or X,Y,Z,TX,TY,TZ"),
        ("1,2,x,0,0,0", "must be frame-all, follow NAME or X,Y,Z,TX,TY,TZ"),
        ("1,2,nan,0,0,0", "the six numbers must be finite"),
        ("1,1,1,1,1,1", "the eye and the point looked at are the same point"),
        ("0,0,5,0,0,0", "looks straight up or down"),
    ],
)
def test_parse_camera_refuses(text: str, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        parse_camera(text)


def test_look_from_puts_the_eye_there() -> None:
    camera = OrbitCamera(640, 360, shift_x=100.0)
    camera.look_from(np.array([4.0, -6.0, 3.0]), np.array([0.0, 1.0, 0.5]))
    assert_allclose(camera.eye, [4.0, -6.0, 3.0], atol=1e-9)
    assert_allclose(camera.project(np.array([[0.0, 1.0, 0.5]]))[0], [320 + 100, 180], atol=1e-6)


def test_fit_fills_the_free_part_of_the_picture() -> None:
    camera = OrbitCamera(640, 360, shift_x=80.0)  # a 160 pixel panel on the left
    rng = np.random.default_rng(3)
    points = rng.uniform([-5, -2, 0], [3, 6, 0.4], (500, 3))
    camera.fit(points, border=0.05)
    pixels = camera.project(points)
    low, high = pixels.min(axis=0), pixels.max(axis=0)
    assert low[0] >= 160 + 0.05 * 480 - 1e-6 and high[0] <= 640 - 0.05 * 640 + 1e-6
    assert low[1] >= 0.05 * 360 - 1e-6 and high[1] <= 360 - 0.05 * 360 + 1e-6
    # tight: one side or the other touches the border (not a loose bounding sphere)
    slack = np.array([low[0] - (160 + 24), 640 - 32 - high[0], low[1] - 18, 342 - high[1]])
    assert slack.min() < 2.0


@pytest.mark.parametrize("shift_x", [0.0, 140.0])  # no panel, the HUD's panel
def test_fit_frames_every_point_tightly_whatever_the_view(shift_x: float) -> None:
    from ecs_tentacles.render.camera import FIT_BORDER

    rng = np.random.default_rng(11)
    for _ in range(40):
        camera = OrbitCamera(yaw=rng.uniform(-3, 3), pitch=rng.uniform(0.1, 1.4), shift_x=shift_x)
        points = rng.normal(0.0, rng.uniform(0.5, 20.0), (int(rng.integers(2, 400)), 3))
        points[:, 2] = np.abs(points[:, 2]) * 0.1  # a crowd on the ground
        camera.fit(points)
        x, y = camera.project(points).T
        left = 2 * shift_x + FIT_BORDER * (camera.width - 2 * shift_x)  # right of the panel
        right = camera.width * (1 - FIT_BORDER)
        bottom, top = FIT_BORDER * camera.height, camera.height * (1 - FIT_BORDER)
        assert (x >= left - 1).all() and (x <= right + 1).all()
        assert (y >= bottom - 1).all() and (y <= top + 1).all()
        gaps = [x.min() - left, right - x.max(), y.min() - bottom, top - y.max()]
        assert min(gaps) < 1.0  # as near as it can be: some point touches a bound
