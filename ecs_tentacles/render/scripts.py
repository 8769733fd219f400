"""The sandbox's scripting window: failed systems in red, hot reloads, re-enable buttons.

When a system raises inside the sandbox's frame loop (`World.step(on_failure=...)`),
`failed` disables it (`schedule.disable`), logs the failure with the user's traceback
(logger `ecs_tentacles.scripting`) and lists it here: the system, its plugin, the
frame and the exception, with a "re-enable" button; the sandbox keeps running. Every
`INTERVAL` seconds `poll` asks the `Reloader` whether a plugin file changed, and a
reload adds a line ("reloaded mywave.py (wave)", or why the old code keeps running);
a reloaded system runs again, so its failure leaves the list.

The window sits at the top right, over the 3D view, and only when it has something
to say.
"""

from __future__ import annotations

import logging
from collections import deque
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from imgui_bundle import imgui

from ecs_tentacles.reload import Reload, Reloader

if TYPE_CHECKING:
    from ecs_tentacles.render.gui import Gui
    from ecs_tentacles.system import SystemFailure
    from ecs_tentacles.world import World

log = logging.getLogger("ecs_tentacles.scripting")
RED = (0.78, 0.05, 0.05, 1.0)
GREEN = (0.05, 0.45, 0.15, 1.0)
NOTES = 4  # reload lines kept
WIDTH = 0.42  # of the window's width, at most


@dataclass(frozen=True)
class Failure:
    """A system the sandbox disabled because it raised."""

    label: str
    plugin: str
    frame: int
    error: str  # "ZeroDivisionError: division by zero"

    @property
    def headline(self) -> str:
        owner = f" (plugin {self.plugin})" if self.plugin else ""
        return f"{self.label}{owner} failed at frame {self.frame}, disabled"


class Scripts:
    """Failures and reloads of the user's systems in one sandbox world."""

    def __init__(self, window: Any):
        self.window = window
        self.failures: list[Failure] = []
        self.notes: deque[tuple[bool, str]] = deque(maxlen=NOTES)  # (ok, line)
        self.world: World | None = None
        self.reloader: Reloader | None = None

    def attach(self, world: World) -> None:
        """Watch a (new) world's plugin files; forget the old world's failures."""
        self.world = world
        self.failures.clear()
        self.reloader = Reloader(world)

    # -- events ------------------------------------------------------------------------
    def failed(self, failure: SystemFailure) -> None:
        """A system raised: disable it, log it, show it (`World.step(on_failure=...)`)."""
        assert self.world is not None
        self.world.schedule.disable(failure.label)
        error = failure.error
        text = " ".join(str(error).split())
        self.failures = [f for f in self.failures if f.label != failure.label]
        self.failures.append(
            Failure(
                failure.label,
                failure.system.plugin,
                failure.frame,
                type(error).__name__ + (f": {text}" if text else ""),
            )
        )
        log.error("%s; system disabled\n%s", failure, failure.user_traceback().rstrip())

    def poll(self, now: float | None = None) -> list[Reload]:
        """Reload changed plugin files (at most every `INTERVAL` s); note what happened."""
        if self.reloader is None:
            return []
        done = self.reloader.poll(now)
        for reload in done:
            self.note(reload)
        return done

    def note(self, reload: Reload) -> None:
        self.say(reload.error is None, reload.message)
        fixed = set(reload.swapped) | set(reload.removed)
        self.failures = [f for f in self.failures if f.label not in fixed]

    def say(self, ok: bool, line: str) -> None:
        """Add a line to the window (green when `ok`, else red) and to the log."""
        self.notes.append((ok, line))
        (log.info if ok else log.warning)("%s", line)

    def enable(self, label: str) -> None:
        """Run a disabled system again (the "re-enable" button)."""
        assert self.world is not None
        self.world.schedule.enable(label)
        self.failures = [f for f in self.failures if f.label != label]

    # -- drawing -----------------------------------------------------------------------
    def draw(self, gui: Gui) -> None:
        """The window at the top right, when there is a failure or a reload to show."""
        if not self.failures and not self.notes:
            return
        width = float(self.window.width) * WIDTH
        imgui.set_next_window_pos((float(self.window.width) - 8.0, 8.0), 0, (1.0, 0.0))
        imgui.set_next_window_size((width, 0.0))  # as tall as its lines need
        flags = imgui.WindowFlags_.no_move | imgui.WindowFlags_.no_resize
        flags |= imgui.WindowFlags_.no_collapse | imgui.WindowFlags_.no_saved_settings
        imgui.begin("Scripts", None, flags)
        gui.window_rect("scripts")
        for failure in list(self.failures):
            imgui.push_style_color(imgui.Col_.text, RED)
            imgui.text_wrapped(failure.headline)
            gui.item(f"failure {failure.label}")
            imgui.text_wrapped(failure.error)
            gui.item(f"error {failure.label}")
            imgui.pop_style_color()
            if imgui.button(f"re-enable {failure.label}"):
                self.enable(failure.label)
            gui.item(f"enable {failure.label}")
        for i, (ok, line) in enumerate(self.notes):
            imgui.push_style_color(imgui.Col_.text, GREEN if ok else RED)
            imgui.text_wrapped(line)
            imgui.pop_style_color()
            gui.item(f"note {i}")
        if self.notes and imgui.small_button("clear"):
            self.notes.clear()
        gui.item("clear notes")
        imgui.end()
