"""The creature creator window (thesis IV.A.2): design a creature, see it, export it.

A thin layer over `ecs_tentacles.creator.CreatureDesign`. Left panel, top: the
uniform settings (mantle radius and height, tentacle count, first link's length and
radius, links, end scale) and "Build creature". Below: pick a tentacle (< >) and
change its length, radius and end scale, add or remove a link. "Export" writes the
scene JSON. The 3D view shows the creature exactly as the exported scene builds it
(it is built from that scene); the selected tentacle is drawn in yellow.

Call `ecs_tentacles.render.configure(headless=...)` before importing this module.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import pyglet
from pyglet.gui import Frame, PushButton, Slider

from ecs_tentacles.components import Creature, Tentacle, Transform
from ecs_tentacles.creator import CreatureDesign, DesignError
from ecs_tentacles.creator.limits import Setting, editor_setting
from ecs_tentacles.render.hud import TEXT
from ecs_tentacles.render.output import save_png
from ecs_tentacles.render.renderer import Renderer

if TYPE_CHECKING:
    from pyglet.customtypes import AnchorX
    from pyglet.image import AbstractImage

SELECTED = (1.0, 0.85, 0.2, 1.0)
ROW = 30
PANEL_WIDTH = 300  # the creator's panel: pyglet widgets placed at fixed pixels


# the sliders: labels and ranges from the scene schema's `x-editor` marks
UNIFORM = (
    editor_setting("mantle_radius", "mantle", "radius"),
    editor_setting("mantle_height", "mantle", "height"),
    editor_setting("count", "tentacles", "count"),
    editor_setting("link_length", "tentacles", "link_length"),
    editor_setting("link_radius", "tentacles", "link_radius"),
    editor_setting("links", "tentacles", "links"),
    editor_setting("end_scale", "tentacles", "end_scale"),
)
PER_TENTACLE = tuple(
    editor_setting(name, "tentacles", name, short=True)
    for name in ("link_length", "link_radius", "end_scale")
)


def _image(width: int, height: int, colour: tuple[int, int, int, int]) -> AbstractImage:
    return pyglet.image.SolidColorImagePattern(colour).create_image(width, height)


class Creator:
    """The creator window and its widgets, bound to one `CreatureDesign`."""

    def __init__(
        self,
        design: CreatureDesign,
        out: str | os.PathLike[str],
        *,
        width: int = 1280,
        height: int = 720,
        headless: bool = False,
    ):
        self.design = design
        self.out = Path(out)
        self.headless = headless
        self.window = pyglet.window.Window(
            width, height, caption="ecs_tentacles creator", visible=not headless
        )
        self.batch = pyglet.graphics.Batch()
        self.frame = Frame(self.window, cell_size=32)
        self._keep: list[object] = []
        self.buttons: list[PushButton] = []
        self.values: dict[str, float] = {}
        self.uniform: dict[str, tuple[Slider, pyglet.text.Label, Setting]] = {}
        self.per_tentacle: dict[str, tuple[Slider, pyglet.text.Label, Setting]] = {}
        self.status = self._label(12, 14, "")
        self._layout()
        self.world = design.preview_world()
        self.renderer = Renderer(self.world, width, height)
        self.renderer.camera.shift_x = PANEL_WIDTH / 2
        self._show()
        self.window.push_handlers(self)

    # -- widgets ---------------------------------------------------------------------
    def _label(
        self, x: float, y: float, text: str, anchor_x: AnchorX = "left", weight: str = "normal"
    ) -> pyglet.text.Label:
        label = pyglet.text.Label(
            text, x=x, y=y, font_size=10, color=TEXT, batch=self.batch, anchor_x=anchor_x,
            weight=weight,
        )  # fmt: skip
        self._keep.append(label)
        return label

    def _button(
        self, x: int, y: int, width: int, text: str, action: Callable[[], None]
    ) -> PushButton:
        button = PushButton(
            x,
            y,
            _image(width, 22, (150, 160, 175, 255)),
            _image(width, 22, (190, 198, 210, 255)),
            batch=self.batch,
        )
        button.set_handler("on_release", lambda widget: self._do(action))
        self.frame.add_widget(button)
        self._label(x + width / 2, y + 6, text, anchor_x="center")
        self.buttons.append(button)
        return button

    def _slider(
        self,
        y: int,
        setting: Setting,
        table: dict[str, tuple[Slider, pyglet.text.Label, Setting]],
        on_change: Callable[[], None] | None,
    ) -> None:
        """A labelled slider; `on_change` applies it at once (None: wait for a button)."""
        slider = Slider(
            112,
            y,
            _image(120, 6, (90, 96, 104, 255)),
            _image(10, 18, (60, 110, 200, 255)),
            edge=5,
            batch=self.batch,
        )

        def changed(widget: Slider, value: float) -> None:
            if not self._refreshing:
                table[setting.name][1].text = self._shown(setting, self._value(setting, value))
                if on_change is not None:
                    self._do(on_change)

        slider.set_handler("on_change", changed)
        self.frame.add_widget(slider)
        self._label(12, y + 2, setting.label)
        table[setting.name] = (
            slider,
            self._label(PANEL_WIDTH - 6, y + 2, "", anchor_x="right"),
            setting,
        )

    def _layout(self) -> None:
        self._refreshing = False
        top = self.window.height - 20
        self._label(12, top, "creature", weight="bold")
        for i, setting in enumerate(UNIFORM):
            self._slider(top - (i + 1) * ROW - 8, setting, self.uniform, None)  # "Build" applies
        y = top - (len(UNIFORM) + 1) * ROW - 14
        self._button(12, y, PANEL_WIDTH - 24, "Build creature", self.build)
        y -= ROW + 16
        self._button(12, y, 24, "<", lambda: self.select_step(-1))
        self._button(PANEL_WIDTH - 36, y, 24, ">", lambda: self.select_step(1))
        self.selection = self._label(PANEL_WIDTH / 2, y + 6, "", anchor_x="center")
        for i, setting in enumerate(PER_TENTACLE):
            self._slider(y - (i + 1) * ROW - 8, setting, self.per_tentacle, self.apply_tentacle)
        y -= (len(PER_TENTACLE) + 1) * ROW + 14
        half = (PANEL_WIDTH - 36) // 2
        self._button(12, y, half, "+ link", lambda: self.design.add_link())
        self._button(24 + half, y, half, "- link", lambda: self.design.remove_link())
        self._button(12, y - ROW - 6, PANEL_WIDTH - 24, "Export", self.export)
        self.background = pyglet.shapes.Rectangle(
            0,
            0,
            PANEL_WIDTH,
            self.window.height,
            color=(245, 247, 250, 225),
            batch=self.batch,
            group=pyglet.graphics.Group(order=-1),
        )

    @staticmethod
    def _value(setting: Setting, position: float) -> float:
        value = setting.low + (setting.high - setting.low) * position / 100.0
        return float(round(value)) if setting.whole else value

    @staticmethod
    def _shown(setting: Setting, value: float) -> str:
        return f"{value:.0f}" if setting.whole else f"{value:.3f}"

    def slider_value(self, name: str, table: str = "uniform") -> float:
        """The design value a slider currently shows."""
        slider, _, setting = (self.uniform if table == "uniform" else self.per_tentacle)[name]
        return self._value(setting, slider.value)

    # -- actions -----------------------------------------------------------------------
    def _do(self, action: Callable[[], None]) -> None:
        """Run an edit; a refused value shows its message instead of changing anything."""
        try:
            action()
        except DesignError as error:
            self.status.text = str(error)
            return
        self._show()

    def build(self) -> None:
        """The "Build creature" button: every tentacle from the uniform settings."""
        value = self.slider_value
        self.design.build(
            mantle_radius=value("mantle_radius"),
            mantle_height=value("mantle_height"),
            count=int(value("count")),
            links=int(value("links")),
            link_length=value("link_length"),
            link_radius=value("link_radius"),
            end_scale=value("end_scale"),
        )
        self.status.text = f"built {len(self.design.tentacles)} tentacles"

    def select_step(self, step: int) -> None:
        choices: list[int | None] = [None, *range(len(self.design.tentacles))]
        current = choices.index(self.design.selected)
        self.design.select(choices[(current + step) % len(choices)])

    def apply_tentacle(self) -> None:
        """Per-tentacle sliders moved: change the selected tentacle."""
        if self.design.selected is not None:
            value = self.slider_value
            self.design.set_tentacle(
                link_length=value("link_length", "tentacle"),
                link_radius=value("link_radius", "tentacle"),
                end_scale=value("end_scale", "tentacle"),
            )

    def export(self) -> None:
        self.design.export(self.out)
        self.status.text = f"exported {self.out}"

    # -- view --------------------------------------------------------------------------
    def _show(self) -> None:
        """Rebuild the preview from the design's scene and refresh the widgets."""
        self.world.close()
        self.world = self.design.preview_world()
        self.renderer.set_world(self.world)
        self.renderer.frame_all()
        self.renderer.camera.distance *= 0.8
        selected = self.design.selected
        if selected is not None:
            creature = self.world.component(self.renderer.creature_entities[0], Creature)
            tentacle = self.world.component(creature.tentacles[selected], Tentacle)
            rows = [self.world.component(e, Transform).row for e in tentacle.links]
            self.renderer.link_instances[np.isin(self.renderer.link_rows, rows), 11:15] = SELECTED
        self._refresh_widgets()

    def _refresh_widgets(self) -> None:
        design = self.design
        values = {"mantle_radius": design.mantle_radius, "mantle_height": design.mantle_height}
        values |= {"count": len(design.tentacles), **vars(design.uniform)}
        chosen = (
            design.tentacles[design.selected] if design.selected is not None else design.uniform
        )
        self._refreshing = True
        try:
            for table, source in ((self.uniform, values), (self.per_tentacle, vars(chosen))):
                for slider, label, setting in table.values():
                    value = source[setting.name]
                    slider.value = float(
                        np.clip(100 * (value - setting.low) / (setting.high - setting.low), 0, 100)
                    )
                    label.text = self._shown(setting, value)
        finally:
            self._refreshing = False
        self.selection.text = (
            "no tentacle"
            if design.selected is None
            else f"tentacle {design.selected} ({design.tentacles[design.selected].links} links)"
        )

    def render(self) -> None:
        from pyglet import gl

        self.renderer.draw()
        gl.glDisable(gl.GL_DEPTH_TEST)
        gl.glDisable(gl.GL_CULL_FACE)
        self.batch.draw()
        if not self.headless:
            self.renderer.target.blit_to_window(*self.window.get_framebuffer_size())

    def on_draw(self) -> None:
        self.window.clear()
        self.render()

    def screenshot(self, path: str | os.PathLike[str]) -> Path:
        self.render()
        return save_png(self.renderer.target.read(), path)

    def run(self) -> None:
        pyglet.app.run(1 / 30)

    def close(self) -> None:
        self.world.close()
        self.window.close()
