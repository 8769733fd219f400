"""Locomotion's HUD sections: tune the selected creature's tentacles, see their actions.

"Locomotion" (first in the panel) has, for every selected creature, a slider for each
parameter the scene schema marks with one (`ecs_tentacles.scene.parameters`: speed,
target angle, strength, wave amplitude and frequency), over its range and with its
label and units (strength stops where the servos' damping can hold it), the gait's
choices, a tentacle selector ("all" or one tentacle; tab steps it too), and the shape
a goal click sends a group in (`ecs_tentacles.locomotion.formations`). Every change goes through
`world.resource(Locomotion).set`, the same API scripts use, so it reaches the servos
on the next physics step. "Actions" (last, folded) lists each tentacle's action.
The locomotion plugin's `Panels` entry makes both. Reads and writes the
parameters through `Locomotion`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, SupportsFloat

from imgui_bundle import imgui

from ecs_tentacles.locomotion.formations import SHAPES, FormationChoice
from ecs_tentacles.locomotion.params import Locomotion, settable
from ecs_tentacles.render.gui import Gui, same_line_if_fits, text_width
from ecs_tentacles.render.registries import Panel, SandboxView
from ecs_tentacles.scene.parameters import Parameter, parameter

if TYPE_CHECKING:
    from ecs_tentacles.world import World


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


def locomotion_panels(sandbox: SandboxView) -> list[Panel]:
    """The Locomotion and Actions sections for a sandbox."""
    return [LocomotionPanel(sandbox), ActionsPanel(sandbox)]


class LocomotionPanel(Panel):
    """The selection's tentacle parameters as sliders, bound to `Locomotion`."""

    title = "Locomotion"
    order = -10  # before the sandbox's own sections

    def __init__(self, sandbox: SandboxView):
        self.sandbox = sandbox  # its world and HUD (the tentacle selector steps the HUD's)
        self.creature: int | None = None
        self.tentacle: int | None = None  # None: all tentacles
        self.values: dict[str, object] = {}  # `Locomotion.get`'s

    @property
    def world(self) -> World:
        return self.sandbox.world

    def _number(self, name: str) -> float:
        value = self.values[name]
        if not isinstance(value, SupportsFloat):
            raise TypeError(f"{name}: {value!r} is not a number")
        return float(value)

    def select(self, creature: int | None, tentacle: int | None) -> None:
        self.creature, self.tentacle = creature, tentacle
        self.refresh()

    @property
    def chosen(self) -> tuple[int, ...]:
        """Every selected creature (the sandbox may select many), else the one shown."""
        selection = getattr(self.sandbox, "selection", None)
        if selection is not None and len(selection):
            return tuple(selection.entities)
        return () if self.creature is None else (self.creature,)

    def set_parameter(self, name: str, value: float | str) -> None:
        """Apply a parameter to every selected creature through the locomotion API (a
        chosen tentacle: to each creature that has it; strength: within each one's
        limit)."""
        if self.creature is None:
            return
        undo = getattr(self.sandbox, "undo", None)
        if undo is not None:  # one undoable edit (a drag of the slider too)
            undo.record(self.world, f"set {name}", lambda: self._apply(name, value))
        else:
            self._apply(name, value)
        self.refresh()

    def _apply(self, name: str, value: float | str) -> None:
        api = self.world.resource(Locomotion)
        for creature in self.chosen:
            if name not in settable()[0]:  # creature-wide (the gait)
                api.set(creature, None, **{name: value})
                continue
            if self.tentacle is not None and self.tentacle >= api.tentacle_count(creature):
                continue
            number = float(value)
            if name == "strength":
                number = min(number, api.strength_limit(creature, self.tentacle))
            api.set(creature, tentacle=self.tentacle, **{name: number})

    def refresh(self) -> None:
        """Read the selection's current values from the world."""
        if self.creature is None or not self.world.has_resource(Locomotion):
            self.values = {}
            return
        values = self.world.resource(Locomotion).get(self.creature, self.tentacle or 0)
        if self.tentacle is None:
            values["speed"] = values["creature_speed"]
        self.values = values

    def draw(self, gui: Gui) -> None:
        if self.creature is None:
            return
        if imgui.arrow_button("##previous", imgui.Dir.left):
            self.sandbox.hud.step_tentacle(-1)
        gui.item("previous")
        imgui.same_line()
        if imgui.arrow_button("##next", imgui.Dir.right):
            self.sandbox.hud.step_tentacle(1)
        gui.item("next")
        imgui.same_line()
        imgui.text("all tentacles" if self.tentacle is None else f"tentacle {self.tentacle}")
        gui.item("tentacle")
        # the values and their units in a column beside the sliders, where a handle never
        # covers them
        column = max(text_width(k.unit % v) for k in KNOBS for v in (k.low, k.high))
        column += imgui.get_style().item_spacing.x
        for knob in KNOBS:
            imgui.text(knob.label)
            gui.item(f"{knob.name} label")
            shown = self._number(knob.name) * knob.to_shown
            high = knob.high
            if knob.name == "strength":  # no stronger than the servos' damping holds
                high = self.world.resource(Locomotion).strength_limit(self.creature, self.tentacle)
            flags = imgui.SliderFlags_.logarithmic.value if knob.log else 0
            imgui.set_next_item_width(-column)
            changed, shown = imgui.slider_float(f"##{knob.name}", shown, knob.low, high, "", flags)
            gui.item(knob.name)
            imgui.same_line()
            imgui.text(knob.unit % shown)
            gui.item(f"{knob.name} value")
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
        self._formation(gui)

    def _formation(self, gui: Gui) -> None:
        """How many creatures the sliders move, and the shape a group goal click takes."""
        count = len(self.chosen)
        imgui.text(f"{count} selected: formation" if count > 1 else "group formation")
        gui.item("formation label")
        choice = self.world.resource(FormationChoice)
        for i, shape in enumerate(SHAPES):
            if i:
                same_line_if_fits(text_width(shape))
            if imgui.radio_button(shape, choice.shape == shape):
                choice.shape = shape
            gui.item(f"formation {shape}")


class ActionsPanel(Panel):
    """Each tentacle's current action, for the selected creature."""

    title = "Actions"
    order = 90  # after every other section
    closed = True

    def __init__(self, sandbox: SandboxView):
        self.sandbox = sandbox
        self.creature: int | None = None

    def select(self, creature: int | None, tentacle: int | None) -> None:
        self.creature = creature

    def draw(self, gui: Gui) -> None:
        if self.creature is None:
            return
        world = self.sandbox.world
        for k, action in enumerate(world.resource(Locomotion).actions(self.creature)):
            imgui.text(f"t{k}: {action}")
            gui.item(f"action {k}")
