"""The ground and sky of a still camera are kept and copied: the same picture to the bit
as drawing them, drawn again as soon as the camera moves or the view changes."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pytest


@pytest.fixture
def counted(make_sandbox: Callable[..., Any]) -> tuple[Any, list[int]]:
    """A paused sandbox on rocky ground with its HUD, and a list that grows by one each
    time the ground is drawn (not copied)."""
    sandbox = make_sandbox("rocky_shore")
    sandbox.session.paused = True
    scenery = sandbox.renderer.scenery
    drawn: list[int] = []
    draw = scenery.draw

    def counting(*args: Any, **kwargs: Any) -> int:
        drawn.append(1)
        calls: int = draw(*args, **kwargs)
        return calls

    scenery.draw = counting
    return sandbox, drawn


def _picture(sandbox: Any) -> np.ndarray:
    """The picture right of the HUD's panel (the panel's live numbers change)."""
    sandbox.render()
    picture: np.ndarray = sandbox.renderer.target.read()[:, sandbox.hud.width :]
    return picture


def test_a_still_camera_copies_the_ground_it_kept(counted: tuple[Any, list[int]]) -> None:
    sandbox, drawn = counted
    first = _picture(sandbox)
    calls = sandbox.renderer.draw_calls
    pictures = [_picture(sandbox) for _ in range(3)]
    assert len(drawn) == 2  # the first frame, and the second (kept); then copies
    assert sandbox.renderer.scenery.kept_for is not None
    for picture in pictures:
        assert picture.tobytes() == first.tobytes()
    assert sandbox.renderer.draw_calls == calls


def test_a_moved_camera_or_another_view_draws_the_ground_again(
    counted: tuple[Any, list[int]],
) -> None:
    sandbox, drawn = counted
    for _ in range(3):
        still = _picture(sandbox)
    kept = len(drawn)
    sandbox.renderer.camera.orbit(40.0, 0.0)
    moved = _picture(sandbox)
    assert len(drawn) == kept + 1 and moved.tobytes() != still.tobytes()
    sandbox.renderer.scenery.kept_for = None  # what drawing gives, nothing kept
    sandbox.renderer.scenery.last_for = None
    assert _picture(sandbox).tobytes() == moved.tobytes()
    sandbox.clean = True  # no metre grid: another picture of the same ground
    for _ in range(3):
        clean = _picture(sandbox)
    assert clean.tobytes() != moved.tobytes()
    width = sandbox.hud.width
    sandbox.hud.visible = False  # the panel's strip is drawn now: drawn again
    before = len(drawn)
    sandbox.render()
    assert len(drawn) == before + 1
    assert sandbox.renderer.target.read()[:, :width].std() > 0  # the world under it
