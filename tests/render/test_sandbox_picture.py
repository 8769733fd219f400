"""The world is not drawn under the HUD's opaque panel: the picture is the same to the
bit, and the pixels the panel covers are left as they were until the panel is drawn."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from pyglet import gl


def _world_then_hud(sandbox: Any, covered: int) -> np.ndarray:
    """The world drawn with `covered` pixels scissored off on the left, then the HUD."""
    sandbox.renderer.covered_left = covered
    sandbox.renderer.draw(1.0)
    gl.glDisable(gl.GL_DEPTH_TEST)
    gl.glDisable(gl.GL_CULL_FACE)
    sandbox.hud.draw()
    picture: np.ndarray = sandbox.renderer.target.read()
    return picture


def test_the_picture_with_the_panel_is_the_same_without_the_world_under_it(
    make_sandbox: Callable[..., Any],
) -> None:
    sandbox = make_sandbox("hedgehog_octopus")
    sandbox.session.paused = True  # the same poses for every picture
    sandbox.step(3)
    sandbox.renderer.frame_all()
    sandbox.render()  # the HUD's windows measured
    sandbox.render()
    with_panel = sandbox.renderer.target.read()
    assert sandbox.renderer.covered_left == sandbox.hud.width > 0
    whole_world = _world_then_hud(sandbox, 0)
    assert np.array_equal(with_panel, whole_world)
    assert _world_then_hud(sandbox, sandbox.hud.width).tobytes() == with_panel.tobytes()


def test_the_covered_pixels_are_neither_cleared_nor_drawn(
    make_sandbox: Callable[..., Any],
) -> None:
    sandbox = make_sandbox("hedgehog_octopus", hud=False)
    sandbox.session.paused = True
    sandbox.step(3)
    renderer = sandbox.renderer
    renderer.frame_all()
    renderer.draw(1.0)
    whole = renderer.target.read()
    renderer.target.bind()
    gl.glClearColor(1.0, 0.0, 1.0, 1.0)  # magenta: nothing the world draws
    gl.glClear(gl.GL_COLOR_BUFFER_BIT)
    renderer.covered_left = 100
    renderer.draw(1.0)
    picture = renderer.target.read()
    assert (picture[:, :100] == (255, 0, 255)).all()
    assert np.array_equal(picture[:, 100:], whole[:, 100:])
    assert not gl.glIsEnabled(gl.GL_SCISSOR_TEST)  # the HUD and others draw everywhere
