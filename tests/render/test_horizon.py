"""The world round the scene: a sky gradient, the ground beyond the terrain out to the
horizon, and distance fog toward the sky's horizon colour (pixels read back)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from ecs_tentacles.ground import ground_of
from ecs_tentacles.render.camera import CameraChoice
from ecs_tentacles.render.horizon import HORIZON

HILLS = {"size": [8, 8], "resolution": 33, "height": 0.4, "noise": {"seed": 1}}
EYE, LOOK_AT = (0.0, -14.0, 2.0), (0.0, 0.0, 0.2)  # low, looking across the field


def _low_view(make_sandbox: Callable[..., Any], terrain: bool) -> tuple[Any, np.ndarray]:
    scene: dict[str, Any] = {"version": 1, "creatures": [{"name": "octo", "position": [-0.5, 0]}]}
    if terrain:
        scene["terrain"] = {"heightfield": HILLS}
    sandbox = make_sandbox(scene, hud=False)
    sandbox.aim(CameraChoice("fixed", eye=EYE, target=LOOK_AT))
    sandbox.render()
    return sandbox, sandbox.renderer.target.read().astype(float)


def _at(sandbox: Any, pixels: np.ndarray, point: tuple[float, float, float]) -> np.ndarray:
    x, y = sandbox.renderer.camera.project(np.array([point]))[0]
    assert 0 <= x < pixels.shape[1] and 0 <= y < pixels.shape[0], point
    return pixels[pixels.shape[0] - 1 - round(y), round(x)]


def test_the_top_of_the_picture_is_a_sky_gradient(make_sandbox: Callable[..., Any]) -> None:
    _, pixels = _low_view(make_sandbox, terrain=True)
    top = pixels[:80]  # the horizon is well below these rows
    assert top.std(axis=1).max() < 2.0  # each row one colour
    blueness = top[:, :, 2].mean(axis=1) - top[:, :, 0].mean(axis=1)
    assert blueness[0] > blueness[-1] + 8  # bluer toward the zenith
    assert (np.diff(blueness) <= 0.5).all()  # and steadily so, row by row


def test_the_ground_goes_on_past_the_terrain_into_the_fog(
    make_sandbox: Callable[..., Any],
) -> None:
    sandbox, pixels = _low_view(make_sandbox, terrain=True)
    field = ground_of(sandbox.world).heightfield
    assert field is not None and field.size == (8.0, 8.0)
    low = float(field.heights.min())
    sky = 255 * np.array(HORIZON)
    near, middle, far = (_at(sandbox, pixels, (2.5, y, low)) for y in (8.0, 40.0, 150.0))
    for colour in (near, middle):  # past the field's edge (4 m): sand, not the sky behind
        assert colour[0] > colour[2] + 15
    haze = [float(np.linalg.norm(c - sky)) for c in (near, middle, far)]
    assert haze[0] > haze[1] > haze[2]  # farther ground is fogged toward the sky
    assert haze[2] < 0.2 * haze[0]


def test_the_plane_goes_on_into_the_fog(make_sandbox: Callable[..., Any]) -> None:
    sandbox, pixels = _low_view(make_sandbox, terrain=False)
    sky = 255 * np.array(HORIZON)
    near, far = (_at(sandbox, pixels, (2.5, y, 0.0)) for y in (8.0, 400.0))
    assert near[0] > near[2] + 15  # sand
    assert np.linalg.norm(far - sky) < 0.2 * np.linalg.norm(near - sky)
