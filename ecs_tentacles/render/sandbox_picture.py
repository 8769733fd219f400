"""The sandbox's picture: each frame drawn (the world, then the HUD) into the off-screen
target, shown in the window, and kept as a screenshot (PNG) or a video (MP4).

`SandboxPicture` is a part of `render.sandbox.Sandbox` (one of its bases). It reads the
sandbox's session (its world and clock: `render.session`), renderer, HUD and camera choice;
it writes the window, the HUD's live numbers (`stats`), the files it is asked for and
its own state (`video`, `screenshots`). Nothing here steps the world.
"""

from __future__ import annotations

import os
import time
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from pyglet import gl

from ecs_tentacles.render.on_screen import labels_over
from ecs_tentacles.render.output import VideoWriter, save_png

if TYPE_CHECKING:
    from pyglet.window import BaseWindow

    from ecs_tentacles.render.camera import CameraChoice
    from ecs_tentacles.render.hud import Hud
    from ecs_tentacles.render.renderer import Renderer
    from ecs_tentacles.render.session import SandboxSession
    from ecs_tentacles.world import World


class SandboxPicture:
    """Drawing a sandbox's frame and keeping it (module docstring)."""

    # the sandbox's own, read here
    session: SandboxSession
    renderer: Renderer
    hud: Hud
    window: BaseWindow
    headless: bool
    camera_choice: CameraChoice | None
    clean: bool

    @property
    def world(self) -> World:
        """The world being played (the session's)."""
        return self.session.world

    def _start_picture(self) -> None:
        """No video, no screenshot yet; the live numbers from zero."""
        self.video: VideoWriter | None = None
        self.screenshots = 0  # taken without a path (F12): their numbers in the file name
        self.stats = {"fps": 0.0, "physics_ms": 0.0, "sim_time": 0.0, "rtf": 0.0, "attached": 0}
        self._wall_start = time.perf_counter()
        self._last_draw: float | None = None

    def keep_framed(self, ease: float = 1.0) -> None:
        """With `--camera frame-all`: move `ease` of the way to framing every creature and
        goal as they are now (a video eases; a screenshot snaps)."""
        if self.camera_choice is None or self.camera_choice.kind != "frame-all":
            return
        camera = self.renderer.camera
        target, distance = camera.target.copy(), camera.distance
        self.renderer.frame_all()
        camera.target = target + ease * (camera.target - target)
        camera.distance = distance * (camera.distance / distance) ** ease

    def render(self) -> np.ndarray | None:
        """Draw the world and the HUD off-screen; return the picture if recording."""
        session = self.session
        alpha = 1.0 if session.paused else session.accumulator / session.world.settings.dt
        self.renderer.overlays = self.hud.visible  # editing aids (fur control markers)
        self.renderer.clean = self.hud.clean = self.clean  # none of them (o toggles)
        self.renderer.show_tiers = self.hud.show_tiers
        # the panel is opaque and drawn over the world: no world is drawn under it (a
        # fifth of a 1280 x 720 picture's pixels), when the picture is the window's size
        same_size = (self.renderer.target.width, self.renderer.target.height) == (
            self.window.width,
            self.window.height,
        )
        self.renderer.covered_left = self.hud.width if same_size else 0
        self.renderer.draw(alpha)
        self._update_stats()
        gl.glDisable(gl.GL_DEPTH_TEST)
        gl.glDisable(gl.GL_CULL_FACE)
        self.hud.draw()
        pixels = None
        if self.video is not None:
            pixels = self.renderer.target.read()
            self.video.add(pixels)
        if not self.headless:
            self.renderer.target.blit_to_window(*self.window.get_framebuffer_size())
        return pixels

    def on_draw(self) -> None:
        now = time.perf_counter()
        if self._last_draw is not None:
            self.stats["fps"] = 0.9 * self.stats["fps"] + 0.1 / max(now - self._last_draw, 1e-6)
        self._last_draw = now
        self.window.clear()
        self.render()

    def _update_stats(self) -> None:
        wall = time.perf_counter() - self._wall_start
        self.stats["sim_time"] = self.world.time
        self.stats["rtf"] = self.world.time / wall if wall > 0 else 0.0
        self.stats["attached"] = int(self.world.suckers.attached.sum())
        self.hud.update(self.stats)

    def creature_labels(self) -> list[tuple[str, float, float]]:
        """Each creature's name at the pixel above its mantle (for `hud.name_labels`)."""
        return labels_over(self.world, self.renderer, self.renderer.creature_entities)

    def selected_label(self) -> list[tuple[str, float, float]]:
        """The selected creature's name above it (a crowd's one label), or nothing."""
        selected = self.renderer.selected
        return [] if selected is None else labels_over(self.world, self.renderer, [selected])

    def screenshot(self, path: str | os.PathLike[str] | None = None) -> Path:
        """Save what the camera sees (with the HUD) as a PNG."""
        self.render()
        if path is None:
            self.screenshots += 1
            path = f"ecs_tentacles_{self.screenshots:03d}.png"
        return save_png(self.renderer.target.read(), path)

    def toggle_video(self, path: str | os.PathLike[str] | None = None) -> Path | None:
        """Start recording, or stop and return the finished file."""
        if self.video is None:
            target = path or f"ecs_tentacles_{int(time.time())}.mp4"
            self.video = VideoWriter(
                target, self.window.width, self.window.height, self.world.settings.fps
            )
            return None
        video, self.video = self.video, None
        return video.close()
