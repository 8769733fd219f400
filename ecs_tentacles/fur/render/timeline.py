"""The fur tool's timeline: scrub the take's time, play and pause, key the picked control.

An ImGui window along the bottom of the 3D view. The scrubber spans the take (the
last key, the simulated time, at least `MIN_SPAN` seconds) and shows the selected
creature's keys as ticks. Scrubbing pauses the world and plays the tracks at the
scrubbed time (the rig's `track_time`), exactly as `fur.tracks` evaluates them;
play resumes the world, whose own time drives the tracks again. `Set key` keys the
picked control's chosen attribute at the current time with the chosen easing;
`Delete key` removes the key nearest the current time (within a frame).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Protocol

from imgui_bundle import imgui

from ecs_tentacles.fur.editor import ATTRIBUTES, FurEditor
from ecs_tentacles.numeric.keyframes import EASINGS
from ecs_tentacles.render.gui import Gui, same_line_if_fits, text_width
from ecs_tentacles.render.registries import SandboxView

if TYPE_CHECKING:
    from ecs_tentacles.fur.systems.rig import Rig

MIN_SPAN = 5.0  # seconds the scrubber shows at least
TICK = (0.85, 0.2, 0.15, 1.0)  # key markers


class KeyedPanel(Protocol):
    """What the timeline asks of its panel (`fur.render.furpanel.FurPanel`, which owns
    the timeline: named here by what it does, not imported back)."""

    editor: FurEditor

    def refresh_rig(self) -> None: ...


class Timeline:
    """The timeline window over a sandbox and its fur panel."""

    def __init__(self, sandbox: SandboxView, panel: KeyedPanel):
        self.sandbox = sandbox
        self.panel = panel
        self.attribute = ATTRIBUTES.index("lift")
        self.easing = EASINGS.index("ease")
        self.scrubbed: float | None = None  # the time shown while scrubbing (world paused)

    @property
    def time(self) -> float:
        """The time the tracks are played at."""
        return self.sandbox.world.time if self.scrubbed is None else self.scrubbed

    def span(self) -> float:
        keys = self.panel.editor.key_times()
        return max(MIN_SPAN, self.sandbox.world.time, keys[-1] if keys else 0.0)

    def _rig(self) -> Rig:
        """The running rig system (its `track_time` pins the tracks' clock)."""
        from ecs_tentacles.fur.systems.rig import Rig

        rig = self.sandbox.world.schedule["rig"]
        if not isinstance(rig, Rig):
            raise TypeError(f"the schedule's rig is a {type(rig).__name__}, not the fur Rig")
        return rig

    def scrub(self, time: float) -> None:
        """Pause and show the fur at `time`."""
        self.sandbox.paused = True
        self.scrubbed = max(0.0, float(time))
        self._rig().track_time = self.scrubbed
        self.panel.refresh_rig()  # time moved: the tracks play again

    def play(self, playing: bool) -> None:
        """Resume (the world's time drives the tracks) or pause where it is."""
        self.sandbox.paused = not playing
        if playing:
            self.scrubbed = None
            self._rig().track_time = None

    def set_key(self) -> None:
        editor = self.panel.editor
        if editor.control is not None:
            editor.set_key(
                editor.control, ATTRIBUTES[self.attribute], self.time, EASINGS[self.easing]
            )
            self.panel.refresh_rig()

    def delete_key(self) -> bool:
        editor = self.panel.editor
        if editor.control is None:
            return False
        within = self.sandbox.world.settings.dt
        deleted = editor.delete_key(editor.control, ATTRIBUTES[self.attribute], self.time, within)
        return bool(deleted)

    def draw(self, gui: Gui, left: float) -> None:
        """The window, from x = `left` to the window's right edge, at the bottom."""
        width, height = self.sandbox.window.width, self.sandbox.window.height
        imgui.set_next_window_pos((left, float(height)), 0, (0.0, 1.0))  # bottom-left anchored
        imgui.set_next_window_size((width - left, 0.0))  # as tall as its rows need
        flags = imgui.WindowFlags_.no_move | imgui.WindowFlags_.no_resize
        flags |= imgui.WindowFlags_.no_collapse | imgui.WindowFlags_.no_title_bar
        imgui.begin("Timeline", None, flags)
        gui.window_rect("timeline")
        playing = not self.sandbox.paused
        if imgui.button("Pause" if playing else "Play"):
            self.play(not playing)
        gui.item("play")
        imgui.same_line()
        imgui.set_next_item_width(-1.0)
        span = self.span()
        changed, time = imgui.slider_float("##scrubber", self.time, 0.0, span, "%.2f s")
        gui.item("scrubber")
        if changed:
            self.scrub(time)
        self._ticks(gui, span)
        editor = self.panel.editor
        imgui.text(f"key {editor.control or '-'}")
        gui.item("key control")
        same_line_if_fits(7 * imgui.get_font_size())
        imgui.set_next_item_width(7 * imgui.get_font_size())
        self.attribute = imgui.combo("##attribute", self.attribute, list(ATTRIBUTES))[1]
        gui.item("attribute")  # the picked control's attribute to key
        same_line_if_fits(text_width("Set key"))
        if imgui.button("Set key"):
            self.set_key()
        gui.item("set key")
        same_line_if_fits(text_width("Delete key"))
        if imgui.button("Delete key"):
            self.delete_key()
        gui.item("delete key")
        for i, easing in enumerate(EASINGS):
            label = easing.replace("_", " ")
            same_line_if_fits(text_width(label))
            if imgui.radio_button(easing.replace("_", " "), self.easing == i):
                self.easing = i
            gui.item(f"easing {easing}")
        imgui.end()

    def _ticks(self, gui: Gui, span: float) -> None:
        """Key times as ticks over the scrubber (the selected creature's keys)."""
        x0, y0, x1, y1 = gui.rects["scrubber"]
        draw = imgui.get_window_draw_list()
        colour = imgui.get_color_u32(TICK)
        pad = 2.0 + imgui.get_style().grab_min_size / 2  # ImGui's slider: padding + half grab
        for time in self.panel.editor.key_times():
            x = x0 + pad + (x1 - x0 - 2 * pad) * time / span
            draw.add_line((x, y0), (x, y0 + 0.35 * (y1 - y0)), colour, 2.0)
