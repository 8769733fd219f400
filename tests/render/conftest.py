"""Rendering tests draw off-screen through EGL: configure pyglet before GL loads."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import Any

import pytest

from ecs_tentacles.render import configure

configure(headless=True)

from pyglet.event import EventDispatcher  # noqa: E402  (after configure: pyglet reads it)
from pyglet.window import mouse  # noqa: E402


@pytest.fixture(autouse=True)
def ui_scale_as_the_display_asks() -> Iterator[None]:
    """Each test starts and ends with no user UI scale (`play --ui-scale` sets one)."""
    from ecs_tentacles.render.gui import set_ui_scale

    set_ui_scale(None)
    yield
    set_ui_scale(None)


@pytest.fixture
def make_sandbox() -> Iterator[Callable[..., Any]]:
    """Headless sandboxes (640 x 360 unless told), closed after the test; keywords that
    are `WorldOptions` fields (`allow_systems=True`, `lod=False`) go into its options."""
    from dataclasses import fields

    from ecs_tentacles.options import WorldOptions
    from ecs_tentacles.render.sandbox import Sandbox

    made: list[Sandbox] = []
    option_names = {f.name for f in fields(WorldOptions)}

    def make(scene: Any, **kwargs: Any) -> Sandbox:
        kwargs.setdefault("width", 640)
        kwargs.setdefault("height", 360)
        chosen = {name: kwargs.pop(name) for name in option_names & set(kwargs)}
        sandbox = Sandbox(scene, WorldOptions(**chosen), headless=True, **kwargs)
        made.append(sandbox)
        return sandbox

    yield make
    for sandbox in made:
        sandbox.close()


def event(sandbox: Any, name: str, *args: Any) -> None:
    """Deliver a window event now (a window queues events outside its own loop)."""
    EventDispatcher.dispatch_event(sandbox.window, name, *args)


def pixel(sandbox: Any, point: Any) -> tuple[int, int]:
    """The window pixel (pyglet's: from the bottom left) where world `point` is drawn."""
    import numpy as np

    x, y = sandbox.renderer.camera.project(np.asarray(point, dtype=float)[None])[0]
    return round(float(x)), round(float(y))


def click_at(sandbox: Any, at: tuple[int, int], modifiers: int = 0) -> None:
    """A left press and release at pixel `at` with `modifiers` held."""
    event(sandbox, "on_mouse_press", *at, mouse.LEFT, modifiers)
    event(sandbox, "on_mouse_release", *at, mouse.LEFT, modifiers)


def click_gui(sandbox: Any, x: float, top: float) -> None:
    """Press and release at (x, top) in GUI pixels (from the top left), drawing between."""
    y = round(sandbox.window.height - top)
    event(sandbox, "on_mouse_motion", round(x), y, 0, 0)
    sandbox.render()
    event(sandbox, "on_mouse_press", round(x), y, mouse.LEFT, 0)
    sandbox.render()
    event(sandbox, "on_mouse_release", round(x), y, mouse.LEFT, 0)
    sandbox.render()
    sandbox.render()


def click_item(sandbox: Any, name: str, fraction: float = 0.5) -> None:
    """Click the GUI widget recorded as `name`, at `fraction` of its width."""
    x0, y0, x1, y1 = sandbox.hud.gui.rects[name]
    click_gui(sandbox, x0 + fraction * (x1 - x0), (y0 + y1) / 2)
