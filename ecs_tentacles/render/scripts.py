"""The sandbox's scripting window: failed systems in red, hot reloads, re-enable buttons.

When a system raises inside the sandbox's frame loop (`World.step(on_failure=...)`),
`failed` disables it (`schedule.disable`), logs the failure with the user's traceback
(logger `ecs_tentacles.scripting`) and lists it here: the system, its plugin, the
frame and the exception, with a "re-enable" button; the sandbox keeps running. Every
`INTERVAL` seconds `poll` asks the `Reloader` whether a plugin file changed, and a
reload adds a line ("reloaded mywave.py (wave)", or why the old code keeps running);
a reloaded system runs again, so its failure leaves the list.

The window sits at the top right, over the 3D view, and only when it has something
to say. It is measured before it is drawn whenever its lines change (`Gui.measure_again`:
an ImGui window sized to its content otherwise shows last frame's size for a frame).
"""

from __future__ import annotations

import logging
from collections import deque
from dataclasses import dataclass
from typing import TYPE_CHECKING

from imgui_bundle import imgui

from ecs_tentacles.reload import Reload, Reloader

if TYPE_CHECKING:
    from pyglet.window import BaseWindow

    from ecs_tentacles.render.gui import Gui
    from ecs_tentacles.system import SystemFailure
    from ecs_tentacles.world import World

log = logging.getLogger("ecs_tentacles.scripting")
RED = (0.78, 0.05, 0.05, 1.0)
GREEN = (0.05, 0.45, 0.15, 1.0)
NOTES = 4  # reload lines kept
WIDTH = 0.42  # of the window's width (wider at a large UI scale, where there is room)
EMS = 24  # the least width in font heights, room allowing (the lines wrap less)
MARGIN = 8.0  # pixels from the window's edges


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

    def __init__(self, window: BaseWindow):
        self.window = window
        self.failures: list[Failure] = []
        self.notes: deque[tuple[bool, str]] = deque(maxlen=NOTES)  # (ok, line)
        self.world: World | None = None
        self.reloader: Reloader | None = None
        self._drawn: tuple[tuple[Failure, ...], tuple[tuple[bool, str], ...]] | None = None

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
        """The window at the top right, when there is a failure or a reload to show: as
        tall as its lines (never past the screen's bottom: it scrolls then), "clear" on
        its first row, every button whole at any UI scale."""
        if not self.failures and not self.notes:
            self._drawn = None
            return
        shown = (tuple(self.failures), tuple(self.notes))
        if shown != self._drawn:  # sized from the last frame's lines: measure these first
            gui.measure_again()
            self._drawn = shown
        screen_w, screen_h = float(self.window.width), float(self.window.height)
        panel = gui.windows.get("panel")  # the HUD's panel on the left, if it shows
        room = screen_w - (panel[2] if panel is not None else 0.0) - 2 * MARGIN
        wide = max(WIDTH * screen_w, EMS * imgui.get_font_size())
        width = max(min(wide, room), WIDTH * screen_w)  # beside the HUD when it can be
        imgui.set_next_window_pos((screen_w - MARGIN, MARGIN), 0, (1.0, 0.0))
        imgui.set_next_window_size((width, 0.0))  # as tall as its lines need
        imgui.set_next_window_size_constraints((width, 0.0), (width, screen_h - 2 * MARGIN))
        flags = imgui.WindowFlags_.no_move | imgui.WindowFlags_.no_resize
        flags |= imgui.WindowFlags_.no_collapse | imgui.WindowFlags_.no_saved_settings
        imgui.begin("Scripts", None, flags)
        gui.window_rect("scripts")
        if self.notes:
            if imgui.small_button("clear"):
                self.notes.clear()
            gui.item("clear notes")
        for failure in list(self.failures):
            imgui.push_style_color(imgui.Col_.text, RED)
            imgui.text_wrapped(failure.headline)
            gui.item(f"failure {failure.label}")
            imgui.text_wrapped(failure.error)
            gui.item(f"error {failure.label}")
            imgui.pop_style_color()
            if imgui.button(f"re-enable##{failure.label}"):  # the headline names it
                self.enable(failure.label)
            gui.item(f"enable {failure.label}")
        for i, (ok, line) in enumerate(self.notes):
            imgui.push_style_color(imgui.Col_.text, GREEN if ok else RED)
            imgui.text_wrapped(line)
            imgui.pop_style_color()
            gui.item(f"note {i}")
        imgui.end()
