"""The heads-up display: tune the selected creature's tentacles, see live stats.

Sliders (pyglet.gui) for speed, target angle, strength, wave amplitude and
frequency, over the scene schema's ranges (the API's too), a gait toggle, and a
tentacle selector ("all" or one tentacle). Every change goes through
`world.locomotion.set`, the same API scripts use, so it reaches the servos on the next
physics step. Labels show fps, physics ms, simulated time, real-time factor, attached
suckers and each tentacle's current action.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
import pyglet
from pyglet.gui import Frame, PushButton, Slider, ToggleButton

from ecs_tentacles.components import Creature
from ecs_tentacles.locomotion.params import TENTACLE_RANGES

PANEL_WIDTH = 300
ROW = 34
TEXT = (20, 24, 28, 255)


@dataclass(frozen=True)
class Knob:
    """A slider's parameter and how it is shown; its range is the scene schema's.

    The slider's 0..100 maps onto the parameter's range (`TENTACLE_RANGES`, read from
    the schema) as `low + span * (s / 100) ** curve`: a curve above 1 gives the low
    end, where the defaults sit, more of the slider. An open lower bound (speed > 0)
    starts a thousandth of the span above it.
    """

    name: str
    label: str
    shown: Callable[[float], str]
    curve: float = 1.0

    @property
    def low(self) -> float:
        allowed = TENTACLE_RANGES[self.name]
        return allowed.low + (1e-3 * (allowed.high - allowed.low) if allowed.low_open else 0.0)

    @property
    def high(self) -> float:
        return TENTACLE_RANGES[self.name].high

    def value(self, slider: float) -> float:
        """The parameter value at slider position `slider` (0..100)."""
        return self.low + (self.high - self.low) * (slider / 100.0) ** self.curve

    def slider(self, value: float) -> float:
        """The slider position (0..100) showing `value`."""
        fraction = np.clip((value - self.low) / (self.high - self.low), 0.0, 1.0)
        return float(100.0 * fraction ** (1.0 / self.curve))


KNOBS = (
    Knob("speed", "speed", lambda v: f"{v:.2f}x", curve=2.0),
    Knob("target_angle", "target angle", lambda v: f"{np.degrees(v):.0f} deg"),
    Knob("strength", "strength (kp)", lambda v: f"{v:.1f}", curve=3.0),
    Knob("wave_amplitude", "wave amplitude", lambda v: f"{np.degrees(v):.1f} deg"),
    Knob("wave_frequency", "wave frequency", lambda v: f"{v:.2f} Hz", curve=2.0),
)


def _image(width: int, height: int, colour: tuple[int, int, int, int]) -> Any:
    return pyglet.image.SolidColorImagePattern(colour).create_image(width, height)


class Hud:
    """Widgets and labels bound to a world's locomotion parameters."""

    def __init__(self, window: pyglet.window.Window, world: Any):
        self.window = window
        self.world = world
        self.visible = True
        self.batch = pyglet.graphics.Batch()
        self._keep: list[Any] = []  # labels pyglet would otherwise drop from the batch
        self.frame = Frame(window, cell_size=32)
        self.creature: int | None = None
        self._refreshing = False  # widgets being set from the world, not by the user
        self.tentacle: int | None = None  # None: all tentacles
        top = window.height - 16
        self.title = self._label(16, top, "", weight="bold")
        self.selector = self._label(50, top - ROW, "")
        self.previous = self._button(16, top - ROW - 6, "<", self._previous_tentacle)
        self.next = self._button(PANEL_WIDTH - 40, top - ROW - 6, ">", self._next_tentacle)
        self.sliders: dict[str, tuple[Slider, Any, Knob]] = {}
        for i, knob in enumerate(KNOBS):
            y = top - (i + 2) * ROW - 12
            slider = Slider(
                112,
                y,
                _image(120, 6, (90, 96, 104, 255)),
                _image(10, 18, (60, 110, 200, 255)),
                edge=5,
                batch=self.batch,
            )
            slider.set_handler("on_change", self._changer(knob))
            self.frame.add_widget(slider)
            self._label(16, y + 2, knob.label)
            value = self._label(PANEL_WIDTH - 4, y + 2, "", anchor_x="right")
            self.sliders[knob.name] = (slider, value, knob)
        y = top - (len(KNOBS) + 2) * ROW - 12
        self.gait = ToggleButton(
            120,
            y,
            _image(60, 20, (70, 140, 90, 255)),
            _image(60, 20, (150, 110, 70, 255)),
            batch=self.batch,
        )
        self.gait.set_handler("on_toggle", self._toggle_gait)
        self.frame.add_widget(self.gait)
        self._label(16, y + 4, "gait")
        self.gait_value = self._label(190, y + 4, "")
        self.stats = self._label(16, y - ROW, "", multiline=True, width=PANEL_WIDTH - 20)
        self.actions = self._label(16, y - 4 * ROW, "", multiline=True, width=PANEL_WIDTH - 20)
        self.background = pyglet.shapes.Rectangle(
            0,
            0,
            PANEL_WIDTH,
            window.height,
            color=(245, 247, 250, 215),
            batch=self.batch,
            group=pyglet.graphics.Group(order=-1),
        )

    # -- building --------------------------------------------------------------------
    def _label(self, x: int, y: int, text: str, **kwargs: Any) -> pyglet.text.Label:
        anchor_y: Literal["top", "baseline"] = "top" if kwargs.get("multiline") else "baseline"
        label = pyglet.text.Label(
            text, x=x, y=y, font_size=10, color=TEXT, batch=self.batch, anchor_y=anchor_y, **kwargs
        )
        self._keep.append(label)
        return label

    def _button(self, x: int, y: int, text: str, action: Callable[[], None]) -> PushButton:
        pressed, unpressed = (
            _image(24, 20, (150, 160, 175, 255)),
            _image(24, 20, (190, 198, 210, 255)),
        )
        button = PushButton(x, y, pressed, unpressed, batch=self.batch)
        button.set_handler("on_release", lambda widget: action())
        self.frame.add_widget(button)
        self._label(x + 8, y + 5, text)
        return button

    # -- selection -------------------------------------------------------------------
    def select(self, creature: int | None, tentacle: int | None = None) -> None:
        """Show and edit `creature` (all its tentacles, or tentacle index `tentacle`)."""
        self.creature, self.tentacle = creature, tentacle
        self.refresh()

    def _count(self) -> int:
        return len(self.world.component(self.creature, Creature).tentacles) if self.creature else 0

    def _previous_tentacle(self) -> None:
        self._step_tentacle(-1)

    def _next_tentacle(self) -> None:
        self._step_tentacle(1)

    def _step_tentacle(self, step: int) -> None:
        if self.creature is None:
            return
        choices: list[int | None] = [None, *range(self._count())]
        self.tentacle = choices[(choices.index(self.tentacle) + step) % len(choices)]
        self.refresh()

    # -- editing ---------------------------------------------------------------------
    def _changer(self, knob: Knob) -> Callable[[Slider, float], None]:
        def changed(widget: Slider, value: float) -> None:
            if not self._refreshing:
                self.set_parameter(knob.name, knob.value(value))

        return changed

    def set_parameter(self, name: str, value: float) -> None:
        """Apply a parameter to the selection through the locomotion API."""
        if self.creature is None:
            return
        if name == "strength":  # no stiffer than the damping holds at this physics step
            value = min(value, self.world.locomotion.strength_limit(self.creature, self.tentacle))
        self.world.locomotion.set(self.creature, tentacle=self.tentacle, **{name: float(value)})
        self.refresh()

    def _toggle_gait(self, widget: ToggleButton, pressed: bool) -> None:
        if self.creature is not None and not self._refreshing:
            self.world.locomotion.set(self.creature, gait="coordinated" if pressed else "cyclic")
            self.refresh()

    def refresh(self) -> None:
        """Show the selection's current values."""
        if self.creature is None:
            self.title.text = "click a creature to select it"
            self.selector.text = ""
            return
        creature = self.world.component(self.creature, Creature)
        self.title.text = f"{creature.name}"
        self.selector.text = (
            "all tentacles" if self.tentacle is None else f"tentacle {self.tentacle}"
        )
        values = self.world.locomotion.get(self.creature, self.tentacle or 0)
        if self.tentacle is None:
            values["speed"] = values["creature_speed"]
        self._refreshing = True
        try:
            for slider, label, knob in self.sliders.values():
                value = values[knob.name]
                slider.value = knob.slider(value)
                label.text = knob.shown(value)
            self.gait.value = values["gait"] == "coordinated"
        finally:
            self._refreshing = False
        self.gait_value.text = values["gait"]

    def update(self, stats: dict[str, float]) -> None:
        """Refresh the live numbers."""
        fps = f"fps {stats['fps']:.0f}   " if stats["fps"] > 0 else ""  # no display: no fps
        self.stats.text = (
            f"{fps}physics {stats['physics_ms']:.1f} ms\n"
            f"sim {stats['sim_time']:.1f} s   real-time x{stats['rtf']:.2f}\n"
            f"suckers attached {stats['attached']}"
        )
        if self.creature is not None:
            actions = self.world.locomotion.actions(self.creature)
            self.actions.text = "\n".join(f"t{k}: {a}" for k, a in enumerate(actions))
        else:
            self.actions.text = ""

    def contains(self, x: float, y: float) -> bool:
        """True when (x, y) is over the panel (clicks there are not for the world)."""
        return self.visible and x < PANEL_WIDTH

    def draw(self) -> None:
        if self.visible:
            self.batch.draw()
