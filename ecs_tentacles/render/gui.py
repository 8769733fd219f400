"""Dear ImGui (imgui-bundle) drawn into pyglet's own GL context, windowed or headless.

ImGui's C++ OpenGL 3 backend renders into whatever context is current, so it shares
pyglet's EGL context off-screen (checked on Mesa llvmpipe) and draws into the
sandbox's framebuffer after the 3D scene. Each `Gui` owns one ImGui context and
feeds it pyglet's window events (y flipped: ImGui's origin is the top left).

Panels are built every frame (immediate mode): a panel function calls ImGui
between `begin_frame` and `end_frame`. `item(name)` records the last widget's
rectangle, in pixels from the top left, so tests can check layout, and `contains`
says whether a pixel belongs to the GUI (clicks there are not for the world).
"""

from __future__ import annotations

import math
import time

import pyglet
from imgui_bundle import imgui
from pyglet.window import BaseWindow, key, mouse

BASE_HEIGHT = 720  # the window height at which the GUI is drawn at scale 1
BANNER_WIDTH = 360.0  # a game banner's width (`Gui.begin_banner`) at 17 px a text line

_KEYS = {
    key.TAB: imgui.Key.tab,
    key.LEFT: imgui.Key.left_arrow,
    key.RIGHT: imgui.Key.right_arrow,
    key.UP: imgui.Key.up_arrow,
    key.DOWN: imgui.Key.down_arrow,
    key.HOME: imgui.Key.home,
    key.END: imgui.Key.end,
    key.DELETE: imgui.Key.delete,
    key.BACKSPACE: imgui.Key.backspace,
    key.RETURN: imgui.Key.enter,
    key.ENTER: imgui.Key.keypad_enter,
    key.ESCAPE: imgui.Key.escape,
    key.LCTRL: imgui.Key.left_ctrl,
    key.RCTRL: imgui.Key.right_ctrl,
    key.LSHIFT: imgui.Key.left_shift,
    key.RSHIFT: imgui.Key.right_shift,
    key.A: imgui.Key.a,
    key.C: imgui.Key.c,
    key.V: imgui.Key.v,
    key.X: imgui.Key.x,
    key.Z: imgui.Key.z,
}
_BUTTONS = {mouse.LEFT: 0, mouse.RIGHT: 1, mouse.MIDDLE: 2}


UI_SCALE: dict[str, float | None] = {"scale": None}  # the user's factor (`play --ui-scale`)
SCALE_RANGE = (0.5, 3.0)  # the least and the largest factor, the user's or the display's


def display_scale(window: BaseWindow) -> float:
    """How much larger the display wants the GUI drawn: the window's DPI scale (pyglet's
    `Window.scale`, its DPI over 96) over the stretch its framebuffer already gives the
    picture (a Retina framebuffer is twice the window: what is drawn at window size is
    magnified already), within `SCALE_RANGE`. 1 headless (no display: a picture does not
    depend on the machine) and when the platform does not say."""
    if pyglet.options["headless"]:
        return 1.0
    try:
        dpi_scale = float(window.scale)
        stretch = window.get_framebuffer_size()[0] / window.width
    except (AttributeError, NotImplementedError, TypeError, ZeroDivisionError):
        return 1.0
    ratio = dpi_scale / stretch if stretch > 0 else dpi_scale
    if not math.isfinite(ratio) or ratio <= 0:
        return 1.0
    return min(SCALE_RANGE[1], max(SCALE_RANGE[0], ratio))


def ui_factor(display: float = 1.0) -> float:
    """The user's factor (`set_ui_scale`), or `display` (`display_scale`) if none was given."""
    user = UI_SCALE["scale"]
    return display if user is None else user


def gui_scale(height: int, display: float = 1.0) -> float:
    """Text and spacing scale for a window `height` pixels tall (0.7 to 1.5), times the
    user's `UI_SCALE` (0.5 to 3) or, when none was given, the display's (`display`)."""
    return min(1.5, max(0.7, height / BASE_HEIGHT)) * ui_factor(display)


def set_ui_scale(factor: float | None) -> None:
    """Draw every GUI `factor` times larger (0.5 to 3; `play --ui-scale`); None: as large
    as the display asks (`display_scale`: its DPI, 1 headless)."""
    if factor is not None and not SCALE_RANGE[0] <= factor <= SCALE_RANGE[1]:
        raise ValueError(f"the UI scale must be in [0.5, 3], got {factor}")
    UI_SCALE["scale"] = None if factor is None else float(factor)


def same_line_if_fits(width: float) -> None:
    """Continue the row when an item `width` pixels wide still fits, else start a new one."""
    imgui.same_line()
    if imgui.get_content_region_avail().x < width:
        imgui.new_line()


def text_width(label: str) -> float:
    """Pixels a button or radio button labelled `label` needs (frame padding included)."""
    return float(imgui.calc_text_size(label).x + 2 * imgui.get_frame_height())


class Gui:
    """One ImGui context bound to a pyglet window; draws into the current framebuffer."""

    def __init__(self, window: BaseWindow):
        self.window = window
        self.context: imgui.internal.Context | None = imgui.create_context()
        imgui.set_current_context(self.context)
        io = imgui.get_io()
        io.set_ini_filename("")  # no imgui.ini written into the user's directory
        io.config_input_trickle_event_queue = True  # a press and release are two frames
        imgui.style_colors_light()
        style = imgui.get_style()
        style.window_rounding = 0.0
        self.scale = 1.0
        self.display = display_scale(window)  # the display's factor, read once
        if not imgui.backends.opengl3_init("#version 330"):
            raise RuntimeError("Dear ImGui could not initialise its OpenGL 3 renderer")
        self.rects: dict[str, tuple[float, float, float, float]] = {}
        self.windows: dict[str, tuple[float, float, float, float]] = {}
        self.clips: dict[str, tuple[float, float, float, float]] = {}  # what of each shows
        self._last = time.perf_counter()
        self._in_frame = False
        self.draw_commands = 0
        self.frames = 0  # frames built so far
        self.remeasure = False  # this frame is to be built again before it is drawn

    # -- events: pyglet -> ImGui -------------------------------------------------------
    def _use(self) -> imgui.IO:
        assert self.context is not None, "the GUI is closed"
        imgui.set_current_context(self.context)
        return imgui.get_io()

    def _mouse(self, x: float, y: float) -> imgui.IO:
        io = self._use()
        io.add_mouse_pos_event(float(x), float(self.window.height - y))
        return io

    def on_mouse_motion(self, x: int, y: int, dx: int, dy: int) -> None:
        self._mouse(x, y)

    def on_mouse_press(self, x: int, y: int, button: int, modifiers: int) -> None:
        self._mouse(x, y).add_mouse_button_event(_BUTTONS.get(button, 0), True)

    def on_mouse_release(self, x: int, y: int, button: int, modifiers: int) -> None:
        self._mouse(x, y).add_mouse_button_event(_BUTTONS.get(button, 0), False)

    def on_mouse_drag(self, x: int, y: int, dx: int, dy: int, buttons: int, modifiers: int) -> None:
        self._mouse(x, y)

    def on_mouse_scroll(self, x: int, y: int, scroll_x: float, scroll_y: float) -> None:
        self._mouse(x, y).add_mouse_wheel_event(float(scroll_x), float(scroll_y))

    def on_key_press(self, symbol: int, modifiers: int) -> None:
        self._key(symbol, modifiers, True)

    def on_key_release(self, symbol: int, modifiers: int) -> None:
        self._key(symbol, modifiers, False)

    def _key(self, symbol: int, modifiers: int, down: bool) -> None:
        io = self._use()
        io.add_key_event(imgui.Key.mod_ctrl, bool(modifiers & key.MOD_CTRL))
        io.add_key_event(imgui.Key.mod_shift, bool(modifiers & key.MOD_SHIFT))
        if symbol in _KEYS:
            io.add_key_event(_KEYS[symbol], down)

    def on_text(self, text: str) -> None:
        io = self._use()
        for character in text:
            io.add_input_character(ord(character))

    @property
    def wants_keyboard(self) -> bool:
        """True while a text field has the focus (keys are typed, not shortcuts)."""
        return bool(self._use().want_text_input)

    # -- frames ----------------------------------------------------------------------
    def begin_frame(self) -> None:
        """Start a GUI frame sized and scaled for the window."""
        io = self._use()
        io.display_size = imgui.ImVec2(float(self.window.width), float(self.window.height))
        now = time.perf_counter()
        io.delta_time = max(now - self._last, 1e-4)
        self._last = now
        scale = gui_scale(self.window.height, self.display)
        if scale != self.scale:  # only when the window is resized (or the user's factor set)
            style = imgui.get_style()
            style.scale_all_sizes(scale / self.scale)
            style.font_scale_main = scale
            self.scale = scale
        imgui.backends.opengl3_new_frame()
        imgui.new_frame()
        self.rects.clear()
        self.windows.clear()
        self.clips.clear()
        self.remeasure = False
        self._in_frame = True

    def item(self, name: str) -> None:
        """Record the last widget's rectangle (x0, y0, x1, y1 from the top left)."""
        low, high = imgui.get_item_rect_min(), imgui.get_item_rect_max()
        self.rects[name] = (low.x, low.y, high.x, high.y)

    def window_rect(self, name: str) -> None:
        """Record the current ImGui window's rectangle (`windows`) and the part of it
        where its widgets show unclipped (`clips`: inside the frame, padding, title bar
        and scroll bars); call between begin and end."""
        pos, size = imgui.get_window_pos(), imgui.get_window_size()
        self.windows[name] = (pos.x, pos.y, pos.x + size.x, pos.y + size.y)
        clip = imgui.internal.get_current_window().inner_clip_rect
        self.clips[name] = (clip.min.x, clip.min.y, clip.max.x, clip.max.y)

    def begin_banner(self, title: str, name: str, headline: str, rows: float) -> None:
        """Begin a game's end-of-round banner: a fixed window `rows` text lines high (a
        window sized to fit its contents is hidden on its first frame), centred across
        the window and a third of the way down, without title bar, moving or resizing;
        its rectangle recorded as `name` (`window_rect`) and `headline` on top in
        double-size text. The caller adds its lines and ends it (`imgui.end()`)."""
        width, height = self.window.width, self.window.height
        imgui.set_next_window_pos((width / 2, height * 0.3), 0, (0.5, 0.5))
        line = imgui.get_text_line_height_with_spacing()
        imgui.set_next_window_size((BANNER_WIDTH * line / 17.0, rows * line))
        flags = imgui.WindowFlags_.no_move | imgui.WindowFlags_.no_resize
        flags |= imgui.WindowFlags_.no_collapse | imgui.WindowFlags_.no_title_bar
        imgui.begin(title, None, flags | imgui.WindowFlags_.no_scrollbar)
        self.window_rect(name)
        imgui.push_font(None, 2.0 * imgui.get_style().font_size_base)
        imgui.text(headline)
        imgui.pop_font()

    def measure_again(self) -> None:
        """A window sized to its content changed it this frame: ImGui sizes such a window
        from the content it had the frame before, so build this frame once more before
        drawing it (`Hud.draw`), or it shows clipped for a frame."""
        self.remeasure = True

    def end_frame(self, draw: bool = True) -> int:
        """Draw the frame into the bound framebuffer; return the GL draw calls issued."""
        imgui.render()
        self.frames += 1
        if not draw:
            self._in_frame = False
            return 0
        data = imgui.get_draw_data()
        self.draw_commands = sum(
            data.cmd_lists[i].cmd_buffer.size() for i in range(data.cmd_lists_count)
        )
        imgui.backends.opengl3_render_draw_data(data)
        self._in_frame = False
        return self.draw_commands

    def skip_frame(self) -> None:
        """No GUI this frame (hidden): forget last frame's rectangles."""
        self.rects.clear()
        self.windows.clear()
        self.clips.clear()

    def contains(self, x: float, y: float) -> bool:
        """True when pyglet pixel (x, y) is over one of last frame's GUI windows."""
        top = self.window.height - y
        return any(x0 <= x < x1 and y0 <= top < y1 for x0, y0, x1, y1 in self.windows.values())

    def close(self) -> None:
        """Free the GL objects and the ImGui context (the GL context must be current)."""
        if self.context is None:
            return
        imgui.set_current_context(self.context)
        imgui.backends.opengl3_shutdown()
        imgui.destroy_context(self.context)
        self.context = None
