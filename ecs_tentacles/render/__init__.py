"""Rendering: meshes, camera, OpenGL instanced drawing, HUD and the sandbox window.

`configure(headless=...)` must run before anything imports `pyglet.gl`: pyglet reads
its options when GL is first imported. The pure-numpy parts (`meshes`, `camera`, the
registries plugins fill, `registries`, and the ring helpers, `rings`) import no GL and
can be used anywhere: importing this package imports no pyglet.
"""

from __future__ import annotations


def configure(headless: bool) -> None:
    """Set pyglet's options for a window or for off-screen (EGL) rendering."""
    import pyglet  # here, not above: plugins import `render.registries` in headless worlds

    if "pyglet.gl" in __import__("sys").modules and pyglet.options["headless"] != headless:
        raise RuntimeError(
            "pyglet.gl was imported before ecs_tentacles.render.configure(); "
            "configure rendering first"
        )
    pyglet.options["headless"] = headless
    pyglet.options["debug_gl"] = False
    pyglet.options["shadow_window"] = not headless
