"""The heads-up display: tune the selected creature's tentacles, see live stats.

Drawn with Dear ImGui (`render.gui`): a panel on the left, as wide as the window
allows, in collapsible sections. "Locomotion" has a slider for each parameter the
scene schema marks with one (`ecs_tentacles.scene.parameters`: speed, target angle,
strength, wave amplitude and frequency), over its range and with its label and units
(strength stops where the servos' damping can hold it), the gait's choices, and a tentacle
selector ("all" or one tentacle). Every change goes through
`world.resource(Locomotion).set`, the same API scripts use, so it reaches the servos on
the next physics step. "Stats" shows fps,
physics ms, simulated time, real-time factor and attached suckers; "Physics" the
groups, threads, recoveries and frozen creatures; "Actions" each tentacle's action.
Extra panels (the fur tool) add sections through `sections`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from imgui_bundle import imgui

from ecs_tentacles.components import Creature
from ecs_tentacles.locomotion.params import Locomotion, settable
from ecs_tentacles.render.gui import Gui, gui_scale, same_line_if_fits, text_width
from ecs_tentacles.scene.parameters import Parameter, parameter

PANEL_WIDTH = 300  # the panel's width at scale 1 (the creator still uses it as is)
PANEL_SHARE = 0.4  # the panel never covers more than this share of the window's width
TEXT = (20, 24, 28, 255)


def panel_width(width: int, height: int) -> int:
    """The HUD panel's width in pixels for a window of this size."""
    return int(min(PANEL_WIDTH * gui_scale(height), PANEL_SHARE * width))


@dataclass(frozen=True)
class Knob:
    """A slider for one parameter of the table, shown in the scene's units.

    The parameter's range (the scene schema's, the API's too) bounds the slider; `log`
    sliders give the low end, where the defaults sit, more room. An open lower bound
    (speed > 0) starts a thousandth of the span above it.
    """

    parameter: Parameter

    @property
    def name(self) -> str:
        return self.parameter.api

    @property
    def label(self) -> str:
        return self.parameter.label

    @property
    def unit(self) -> str:
        """The slider's printf format: the slider's digits, then the scene's units."""
        p = self.parameter
        assert p.slider is not None
        return f"%.{p.slider.digits}f" + (f" {p.units}" if p.units else "")

    @property
    def to_shown(self) -> float:
        """Shown value = stored value x this (degrees for radians)."""
        return 1.0 / self.parameter.factor

    @property
    def log(self) -> bool:
        return bool(self.parameter.slider and self.parameter.slider.log)

    @property
    def low(self) -> float:
        allowed = self.parameter.range
        assert allowed is not None
        low = allowed.low + (1e-3 * (allowed.high - allowed.low) if allowed.low_open else 0.0)
        return low * self.to_shown

    @property
    def high(self) -> float:
        assert self.parameter.range is not None
        return self.parameter.range.high * self.to_shown


def knobs() -> tuple[Knob, ...]:
    """A slider per run-time tentacle parameter with a `slider` entry, in its order."""
    marked = [p for p in settable()[0].values() if p.slider is not None]
    return tuple(Knob(p) for p in sorted(marked, key=lambda p: p.slider.order if p.slider else 0))


KNOBS = knobs()


CLOSED = ("Actions", "Plugins")  # sections that start folded


class Hud:
    """The sandbox's panel, bound to a world's locomotion parameters."""

    def __init__(self, window: Any, world: Any, *, visible: bool = True):
        self.window = window
        self.world = world
        self.visible = visible
        self.gui = Gui(window)
        self.creature: int | None = None
        self.tentacle: int | None = None  # None: all tentacles
        self.stats: dict[str, float] = {}
        self.values: dict[str, Any] = {}
        self.sections: list[tuple[str, Callable[[Gui], None]]] = []  # (title, draw)
        self.windows: list[Callable[[Gui], None]] = []  # more ImGui windows (the timeline)
        self._fold: set[str] = set()  # sections to close on the next frame
        self.name_labels = False  # creatures' names over them (even with the panel hidden)
        self.label_at: Callable[[], list[tuple[str, float, float]]] = list  # (text, x, y)

    # -- selection -------------------------------------------------------------------
    def select(self, creature: int | None, tentacle: int | None = None) -> None:
        """Show and edit `creature` (all its tentacles, or tentacle index `tentacle`)."""
        self.creature, self.tentacle = creature, tentacle
        self.refresh()

    @property
    def title(self) -> str:
        if self.creature is None:
            return "click a creature to select it"
        return str(self.world.component(self.creature, Creature).name)

    def _count(self) -> int:
        return len(self.world.component(self.creature, Creature).tentacles) if self.creature else 0

    def step_tentacle(self, step: int) -> None:
        """Select the next (+1) or previous (-1) tentacle, through "all"."""
        if self.creature is None:
            return
        choices: list[int | None] = [None, *range(self._count())]
        self.tentacle = choices[(choices.index(self.tentacle) + step) % len(choices)]
        self.refresh()

    # -- editing ---------------------------------------------------------------------
    def set_parameter(self, name: str, value: float | str) -> None:
        """Apply a parameter to the selection through the locomotion API."""
        if self.creature is None:
            return
        if name not in settable()[0]:  # creature-wide (the gait)
            self.world.resource(Locomotion).set(self.creature, **{name: value})
        else:
            self.world.resource(Locomotion).set(
                self.creature, tentacle=self.tentacle, **{name: float(value)}
            )
        self.refresh()

    def refresh(self) -> None:
        """Read the selection's current values from the world."""
        if self.creature is None or not self.world.has_resource(Locomotion):
            self.values = {}
            return
        values = self.world.resource(Locomotion).get(self.creature, self.tentacle or 0)
        if self.tentacle is None:
            values["speed"] = values["creature_speed"]
        self.values = values

    def update(self, stats: dict[str, float]) -> None:
        """Keep the live numbers for the next draw."""
        self.stats = dict(stats)

    # -- drawing ---------------------------------------------------------------------
    def fold(self, *sections: str) -> None:
        """Close these sections (as a click on their headers would)."""
        self._fold.update(sections)

    def contains(self, x: float, y: float) -> bool:
        """True when pyglet pixel (x, y) is over the panel (clicks there are not for the world)."""
        return self.visible and (x < self.width or self.gui.contains(x, y))

    @property
    def width(self) -> int:
        """Pixels the panel covers on the left (0 when hidden)."""
        return panel_width(self.window.width, self.window.height) if self.visible else 0

    def draw(self) -> int:
        """Build and draw the panel; return the GL draw calls it issued."""
        if not self.visible and not self.name_labels:
            self.gui.skip_frame()
            return 0
        if not self.gui.frames:  # windows that fit their content know their size from frame 2
            self._build()
            self.gui.end_frame(draw=False)
        self._build()
        return self.gui.end_frame()

    def _build(self) -> None:
        gui = self.gui
        gui.begin_frame()
        if self.name_labels:
            self._name_labels()
        if not self.visible:
            return
        imgui.set_next_window_pos((0.0, 0.0))
        imgui.set_next_window_size((float(self.width), float(self.window.height)))
        flags = imgui.WindowFlags_.no_move | imgui.WindowFlags_.no_resize
        imgui.begin("ecs_tentacles", None, flags | imgui.WindowFlags_.no_collapse)
        gui.window_rect("panel")
        imgui.text(self.title)
        gui.item("title")
        moving = self.world.has_resource(Locomotion)  # the locomotion plugin is on
        own: list[tuple[str, Callable[[Gui], None]]] = [
            *([("Locomotion", self._locomotion)] if moving else []),
            ("Stats", self._stats),
            ("Physics", self._physics),
            ("Plugins", self._plugins),
        ]
        last = [("Actions", self._actions)] if moving else []
        for name, build in [*own, *self.sections, *last]:
            if name in self._fold:
                imgui.set_next_item_open(False)
                self._fold.discard(name)
            opened = imgui.collapsing_header(
                name, imgui.TreeNodeFlags_.default_open if name not in CLOSED else 0
            )
            gui.item(name)
            if opened:
                build(gui)
        imgui.end()
        for window in self.windows:
            window(gui)

    def _name_labels(self) -> None:
        """Each `label_at` text centred at its pixel (pyglet's y), on a dark plate."""
        draw = imgui.get_foreground_draw_list()
        pad = 4.0 * self.gui.scale
        for text, x, y in self.label_at():
            size = imgui.calc_text_size(text)
            left, top = x - size.x / 2, self.window.height - y - size.y / 2
            plate = imgui.get_color_u32((0.1, 0.1, 0.12, 0.75))
            draw.add_rect_filled(
                (left - pad, top - pad), (left + size.x + pad, top + size.y + pad), plate, pad
            )
            draw.add_text((left, top), imgui.get_color_u32((1.0, 1.0, 1.0, 1.0)), text)

    def _locomotion(self, gui: Gui) -> None:
        if self.creature is None:
            return
        if imgui.arrow_button("##previous", imgui.Dir.left):
            self.step_tentacle(-1)
        gui.item("previous")
        imgui.same_line()
        if imgui.arrow_button("##next", imgui.Dir.right):
            self.step_tentacle(1)
        gui.item("next")
        imgui.same_line()
        imgui.text("all tentacles" if self.tentacle is None else f"tentacle {self.tentacle}")
        gui.item("tentacle")
        for knob in KNOBS:
            imgui.text(knob.label)
            gui.item(f"{knob.name} label")
            imgui.set_next_item_width(-1.0)
            shown = float(self.values[knob.name]) * knob.to_shown
            high = knob.high
            if knob.name == "strength":  # no stronger than the servos' damping holds
                high = self.world.resource(Locomotion).strength_limit(self.creature, self.tentacle)
            flags = imgui.SliderFlags_.logarithmic.value if knob.log else 0
            changed, shown = imgui.slider_float(
                f"##{knob.name}", shown, knob.low, high, knob.unit, flags
            )
            gui.item(knob.name)
            if changed:
                self.set_parameter(knob.name, min(shown, high) / knob.to_shown)
        gaits = parameter("locomotion", "gait")
        imgui.text(gaits.label)
        gui.item("gait label")
        for i, gait in enumerate(gaits.choices):
            if i:
                same_line_if_fits(text_width(gait))
            if imgui.radio_button(gait, self.values["gait"] == gait):
                self.set_parameter("gait", gait)
            gui.item(f"gait {gait}")

    def _stats(self, gui: Gui) -> None:
        stats = self.stats
        if stats.get("fps", 0.0) > 0:  # no display: no fps
            imgui.text(f"fps {stats['fps']:.0f}")
            gui.item("fps")
        for name, text in (
            ("physics ms", f"physics {stats.get('physics_ms', 0.0):.1f} ms"),
            ("sim", f"sim {stats.get('sim_time', 0.0):.1f} s"),
            ("rtf", f"real-time x{stats.get('rtf', 0.0):.2f}"),
            ("attached", f"suckers attached {int(stats.get('attached', 0))}"),
        ):
            imgui.text(text)
            gui.item(name)

    def _physics(self, gui: Gui) -> None:
        physics = self.world.physics
        health = physics.health
        for name, text in (
            ("groups", f"groups {len(physics.groups)} on {physics.threads} threads"),
            ("recoveries", f"recoveries {health.recoveries}   frozen {health.frozen}"),
        ):
            imgui.text(text)
            gui.item(name)

    def _plugins(self, gui: Gui) -> None:
        """The plugins on, and every system in frame order with a box to switch it off."""
        imgui.text_wrapped("on: " + ", ".join(p.key for p in self.world.plugins))
        gui.item("plugins on")
        schedule = self.world.schedule
        off = set(schedule.disabled())
        for row in schedule.rows():
            name = row["system"].removesuffix(" (disabled)")
            changed, running = imgui.checkbox(f"{row['stage']:<8} {name}", name not in off)
            gui.item(f"system {name}")
            if changed:
                (schedule.enable if running else schedule.disable)(name)

    def _actions(self, gui: Gui) -> None:
        if self.creature is None:
            return
        for k, action in enumerate(self.world.resource(Locomotion).actions(self.creature)):
            imgui.text(f"t{k}: {action}")
            gui.item(f"action {k}")

    def close(self) -> None:
        self.gui.close()
