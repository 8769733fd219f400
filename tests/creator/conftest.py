"""The creator window's tests draw off-screen through EGL: configure pyglet before GL loads."""

from __future__ import annotations

from ecs_tentacles.render import configure

configure(headless=True)
