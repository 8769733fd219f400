"""Rendering tests draw off-screen through EGL: configure pyglet before GL loads."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import Any

import pytest

from ecs_tentacles.render import configure

configure(headless=True)


@pytest.fixture
def make_sandbox() -> Iterator[Callable[..., Any]]:
    """Headless sandboxes (640 x 360 unless told), closed after the test."""
    from ecs_tentacles.render.sandbox import Sandbox

    made: list[Sandbox] = []

    def make(scene: Any, **kwargs: Any) -> Sandbox:
        kwargs.setdefault("width", 640)
        kwargs.setdefault("height", 360)
        sandbox = Sandbox(scene, headless=True, **kwargs)
        made.append(sandbox)
        return sandbox

    yield make
    for sandbox in made:
        sandbox.close()
