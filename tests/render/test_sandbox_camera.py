"""`play --camera`: frame every creature, follow one, or stand somewhere, headless."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from numpy.testing import assert_allclose

from ecs_tentacles.render.camera import CameraChoice


def _body_rows(sandbox: Any) -> np.ndarray:
    renderer = sandbox.renderer
    return np.concatenate([renderer.mantle_rows, renderer.link_rows])


def test_frame_all_keeps_every_creature_in_the_picture(
    make_sandbox: Callable[..., Any], tmp_path: Path
) -> None:
    sandbox = make_sandbox("rocky_shore")
    sandbox.aim(CameraChoice("frame-all"))
    sandbox.run_headless(90, screenshot=tmp_path / "shot.png", progress=False)
    pixels = sandbox.renderer.camera.project(sandbox.world.transforms.pos[_body_rows(sandbox)])
    left = sandbox.hud.width  # the panel covers the picture's left
    assert left > 0
    assert (pixels[:, 0] > left).all() and (pixels[:, 0] < 640).all()
    assert (pixels[:, 1] > 0).all() and (pixels[:, 1] < 360).all()
    # and fills it: the creatures span most of the free width or height
    span = (pixels.max(axis=0) - pixels.min(axis=0)) / [640 - left, 360]
    assert span.max() > 0.75


def test_follow_keeps_the_creature_at_the_centre(
    make_sandbox: Callable[..., Any], tmp_path: Path
) -> None:
    sandbox = make_sandbox("rocky_shore")
    sandbox.aim(CameraChoice("follow", name="east1"))
    world = sandbox.world
    entity = world.creature("east1")
    mantle = sandbox.renderer.mantle_rows[sandbox.renderer.creature_entities.index(entity)]
    start = world.transforms.pos[mantle].copy()
    sandbox.run_headless(120, screenshot=tmp_path / "shot.png", progress=False)
    now = world.transforms.pos[mantle]
    assert np.linalg.norm(now[:2] - start[:2]) > 0.05  # it crawled, the camera went along
    x, y = sandbox.renderer.camera.project(now[None])[0]
    centre = ((sandbox.hud.width + 640) / 2, 180)
    assert_allclose((x, y), centre, atol=0.05 * 360)


def test_a_fixed_camera_stands_where_it_is_told(make_sandbox: Callable[..., Any]) -> None:
    sandbox = make_sandbox("octopus", hud=False)
    sandbox.aim(CameraChoice("fixed", eye=(3.0, -4.0, 2.0), target=(0.5, 0.0, 0.0)))
    sandbox.step(3)
    sandbox.render()
    assert_allclose(sandbox.renderer.camera.eye, [3.0, -4.0, 2.0], atol=1e-9)
