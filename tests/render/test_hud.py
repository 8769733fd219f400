"""The ImGui HUD: layout without overlaps, scaling, hiding, sections, and its sliders."""

from __future__ import annotations

import itertools
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from PIL import Image
from pyglet.window import key

from ecs_tentacles.cli import main
from ecs_tentacles.locomotion.params import Locomotion
from ecs_tentacles.render.hud import PANEL_SHARE, PANEL_WIDTH, panel_width
from tests.render.conftest import click_gui, click_item, event


def overlaps(rects: dict[str, tuple[float, float, float, float]]) -> list[tuple[str, str]]:
    return [
        (a, b)
        for (a, (ax0, ay0, ax1, ay1)), (b, (bx0, by0, bx1, by1)) in itertools.combinations(
            rects.items(), 2
        )
        if ax0 < bx1 and bx0 < ax1 and ay0 < by1 and by0 < ay1
    ]


@pytest.mark.parametrize("size", [(1280, 720), (640, 360), (320, 240)])
def test_widgets_never_overlap_and_fit_the_panel(
    make_sandbox: Callable[..., Any], size: tuple[int, int]
) -> None:
    sandbox = make_sandbox("hedgehog_octopus", width=size[0], height=size[1])
    sandbox.hud.sections.append(("Extra", lambda gui: None))
    sandbox.render()
    rects = dict(sandbox.hud.gui.rects)
    assert {"speed label", "speed", "wave_amplitude label", "gait label"} <= set(rects)
    assert overlaps(rects) == []
    sandbox.hud.unfold("Physics")  # one section open at a time: Locomotion folds
    sandbox.render()
    assert "models" in sandbox.hud.gui.rects and "speed" not in sandbox.hud.gui.rects
    assert overlaps(sandbox.hud.gui.rects) == []
    x0, y0, x1, y1 = sandbox.hud.gui.windows["panel"]
    assert (x0, y0, x1, y1) == (0, 0, panel_width(*size), size[1])
    assert x1 <= PANEL_SHARE * size[0]
    windows = sandbox.hud.gui.windows
    assert set(windows) == {"panel", "timeline"}  # hedgehog_octopus has fur: the fur tool
    assert overlaps(windows) == []

    def inside(r: tuple[float, ...], w: tuple[float, ...]) -> bool:
        return w[0] <= r[0] and r[2] <= w[2] and w[1] <= r[1]

    assert [n for n, r in rects.items() if not any(inside(r, w) for w in windows.values())] == []


def test_panel_and_text_scale_with_the_window(make_sandbox: Callable[..., Any]) -> None:
    heights = {}
    for size in ((1280, 720), (640, 360)):
        sandbox = make_sandbox("octopus", width=size[0], height=size[1])
        sandbox.render()
        rect = sandbox.hud.gui.rects["speed label"]
        heights[size] = rect[3] - rect[1]
    assert heights[(640, 360)] < 0.8 * heights[(1280, 720)]


def _panel_pixels(pixels: np.ndarray, colour: np.ndarray) -> int:
    return int((pixels == colour).all(axis=2).sum())


def test_no_hud_flag_and_h_key_hide_the_panel(
    make_sandbox: Callable[..., Any], tmp_path: Path
) -> None:
    sandbox = make_sandbox("octopus")
    sandbox.render()
    shown = sandbox.renderer.target.read()
    panel = shown[:, : sandbox.hud.width].reshape(-1, 3)
    colours, counts = np.unique(panel, axis=0, return_counts=True)
    background = colours[counts.argmax()]  # the panel's own colour: most of it
    assert _panel_pixels(shown[:, : sandbox.hud.width], background) > 0.5 * 360 * sandbox.hud.width
    event(sandbox, "on_key_press", key.H, 0)
    assert sandbox.renderer.camera.shift_x == 0.0
    sandbox.render()
    assert _panel_pixels(sandbox.renderer.target.read(), background) == 0
    event(sandbox, "on_key_press", key.H, 0)
    sandbox.render()
    again = sandbox.renderer.target.read()[:, : sandbox.hud.width]
    assert _panel_pixels(again, background) > 0.5 * 360 * sandbox.hud.width
    shot = tmp_path / "bare.png"
    argv = ["play", "octopus", "--headless", "--frames", "2", "--quiet", "--no-hud"]
    assert main([*argv, "--width", "640", "--height", "360", "--screenshot", str(shot)]) == 0
    with Image.open(shot) as image:
        assert _panel_pixels(np.asarray(image), background) == 0


def test_sections_collapse(make_sandbox: Callable[..., Any]) -> None:
    sandbox = make_sandbox("octopus")
    sandbox.render()
    assert "speed" in sandbox.hud.gui.rects and "action 0" not in sandbox.hud.gui.rects
    x0, y0, x1, y1 = sandbox.hud.gui.rects["Locomotion"]
    click_gui(sandbox, (x0 + x1) / 2, (y0 + y1) / 2)
    assert "speed" not in sandbox.hud.gui.rects and "Stats" in sandbox.hud.gui.rects
    x0, y0, x1, y1 = sandbox.hud.gui.rects["Actions"]
    click_gui(sandbox, (x0 + x1) / 2, (y0 + y1) / 2)
    assert "action 7" in sandbox.hud.gui.rects


def test_slider_click_reaches_the_servo_gains(make_sandbox: Callable[..., Any]) -> None:
    sandbox = make_sandbox("octopus")
    world = sandbox.world
    octo = world.creature("octopus")
    sandbox.render()
    x0, y0, x1, y1 = sandbox.hud.gui.rects["strength"]
    click_gui(sandbox, x0 + 0.75 * (x1 - x0), (y0 + y1) / 2)
    kp = world.resource(Locomotion).get(octo, 0)["strength"]
    # the knob jumped to where we clicked, on a logarithmic scale up to what damping holds
    assert 10 < kp < world.resource(Locomotion).strength_limit(octo)
    assert [world.resource(Locomotion).get(octo, k)["strength"] for k in range(8)] == [
        kp
    ] * 8  # "all"
    sandbox.step(1)
    group = world.physics.views[0]
    actuator = group.model.actuator("t3/l00/curl").id
    row = int(world.tentacles.first_link[3])
    assert group.kp[actuator] == pytest.approx(kp * world.motors.gain[row], rel=1e-12)
    x0, y0, x1, y1 = sandbox.hud.gui.rects["gait cyclic"]
    click_gui(sandbox, (x0 + x1) / 2, (y0 + y1) / 2)
    assert world.resource(Locomotion).get(octo, 0)["gait"] == "cyclic"


def test_gui_draw_calls_do_not_grow_with_creatures(make_sandbox: Callable[..., Any]) -> None:
    calls = []
    for scene in ("octopus", "thesis_four_by_six"):
        sandbox = make_sandbox(scene)
        sandbox.render()
        calls.append(sandbox.hud.gui.draw_commands)
    assert calls[0] == calls[1] <= 8


@pytest.mark.parametrize("name", ["speed", "target_angle", "strength", "wave_amplitude"])
def test_each_slider_spans_the_schema_range(name: str) -> None:
    from ecs_tentacles.locomotion.panel import KNOBS
    from ecs_tentacles.scene.ranges import field_range

    (knob,) = [k for k in KNOBS if k.name == name]
    key = {"target_angle": "target_angle_deg", "wave_amplitude": "wave_amplitude_deg"}
    allowed = field_range("tentacles", key.get(name, name))  # scene units, as the HUD shows
    assert knob.high == pytest.approx(allowed.high)
    assert knob.low in allowed  # an open lower bound (speed > 0) is never shown
    assert knob.low - allowed.low <= 1e-3 * (allowed.high - allowed.low)


def test_the_strength_slider_stops_where_the_damping_holds(
    make_sandbox: Callable[..., Any],
) -> None:
    sandbox = make_sandbox("octopus")
    world = sandbox.world
    octo = world.creature("octopus")
    sandbox.render()
    _, y0, x1, y1 = sandbox.hud.gui.rects["strength"]
    click_gui(sandbox, x1 - 1, (y0 + y1) / 2)
    # damping 0.5 at 1/480 s holds at most kp 240 (damping >= strength x step)
    assert world.resource(Locomotion).strength_limit(octo) == pytest.approx(240.0)
    assert world.resource(Locomotion).get(octo, 5)["strength"] == pytest.approx(240.0, rel=1e-3)


def test_the_sliders_are_the_parameter_tables() -> None:
    """Which sliders, their order, labels and units: the schema's `x-parameter` entries."""
    from ecs_tentacles.locomotion.panel import KNOBS
    from ecs_tentacles.scene.schema import load_schema

    tentacles = load_schema()["$defs"]["creature"]["properties"]["tentacles"]["properties"]
    marked = {
        k: v["x-parameter"] for k, v in tentacles.items() if "slider" in v.get("x-parameter", {})
    }
    by_order = sorted(marked, key=lambda k: marked[k]["slider"]["order"])
    assert [k.name for k in KNOBS] == [k.removesuffix("_deg") for k in by_order]
    assert [k.label for k in KNOBS] == [marked[k]["label"] for k in by_order]
    strength = next(k for k in KNOBS if k.name == "strength")
    assert (strength.label, strength.unit, strength.log) == ("strength (kp)", "%.1f N m/rad", True)
    angle = next(k for k in KNOBS if k.name == "target_angle")
    assert angle.unit == "%.0f deg" and angle.to_shown == pytest.approx(180 / np.pi, rel=1e-15)


def test_plugins_section_switches_systems_off_and_on(make_sandbox: Callable[..., Any]) -> None:
    sandbox = make_sandbox("octopus", width=960, height=720)
    sandbox.render()
    x0, y0, x1, y1 = sandbox.hud.gui.rects["Locomotion"]
    click_gui(sandbox, (x0 + x1) / 2, (y0 + y1) / 2)  # fold it: room for the systems
    x0, y0, x1, y1 = sandbox.hud.gui.rects["Plugins"]
    click_gui(sandbox, (x0 + x1) / 2, (y0 + y1) / 2)
    assert "system rig" in sandbox.hud.gui.rects
    x0, y0, x1, y1 = sandbox.hud.gui.rects["system motor_targets"]
    click_gui(sandbox, x0 + 6, (y0 + y1) / 2)  # the box
    assert sandbox.world.schedule.disabled() == ["motor_targets"]
    click_gui(sandbox, x0 + 6, (y0 + y1) / 2)
    assert sandbox.world.schedule.disabled() == []


def test_a_world_without_locomotion_has_no_locomotion_sections(
    make_sandbox: Callable[..., Any],
) -> None:
    off = {"locomotion": False, "suckers": False}
    sandbox = make_sandbox({"version": 1, "plugins": off, "creatures": [{}]})
    sandbox.render()
    assert "Locomotion" not in sandbox.hud.gui.rects and "Actions" not in sandbox.hud.gui.rects
    assert "Plugins" in sandbox.hud.gui.rects


def test_slider_values_sit_beside_the_sliders_where_no_handle_covers_them(
    make_sandbox: Callable[..., Any],
) -> None:
    from imgui_bundle import imgui

    sandbox = make_sandbox("octopus")
    sandbox.render()
    pixels = sandbox.renderer.target.read()
    grab = np.array(imgui.get_style().color_(imgui.Col_.slider_grab.value))[:3] * 255
    rects = sandbox.hud.gui.rects
    for name in ("speed", "target_angle", "strength", "wave_amplitude", "wave_frequency"):
        x0, y0, x1, y1 = (round(v) for v in rects[f"{name} value"])
        assert x0 >= rects[name][2]  # right of its slider
        patch = pixels[y0:y1, x0:x1].reshape(-1, 3).astype(float)
        assert (patch.mean(axis=1) < 128).any()  # the text is there
        assert not (np.abs(patch - grab).max(axis=1) < 30).any(), name  # and no handle on it


def test_the_selection_has_a_name_plate_over_it(make_sandbox: Callable[..., Any]) -> None:
    """A crowd shows one compact label: the selected creature's name on a dark plate."""
    sandbox = make_sandbox(
        {
            "version": 1,
            "creatures": [{"name": f"c{i}", "position": [3.0 * i, 0]} for i in range(12)],
        }
    )
    chosen = sandbox.world.creature("c5")
    sandbox.select(chosen)
    ((text, x, y),) = sandbox.selected_label()
    assert text == "c5"
    sandbox.render()
    pixels = sandbox.renderer.target.read().astype(int)
    top, left = sandbox.window.height - round(y), round(x)
    around = pixels[top - 4 : top + 5, left - 4 : left + 5].max(axis=2)
    assert np.median(around) < 80  # the dark plate is there (its white letters a minority)


def test_the_director_is_in_reach_at_720p_with_locomotion_open_and_fur(
    make_sandbox: Callable[..., Any],
) -> None:
    sandbox = make_sandbox("hedgehog_octopus", width=1280, height=720)
    sandbox.render()
    rects = sandbox.hud.gui.rects
    assert "speed" in rects and "Fur" in rects  # Locomotion open, a furred creature
    assert rects["Director"][3] <= 720  # its header is on screen: no scrolling
    click_item(sandbox, "Director")
    assert "speed" not in sandbox.hud.gui.rects  # opening it folded Locomotion
    director = [r for n, r in sandbox.hud.gui.rects.items() if r[1] > rects["Director"][3]]
    assert director and all(r[3] <= 720 for r in director)  # its widgets fit too


def test_ui_scale_makes_the_hud_larger(make_sandbox: Callable[..., Any]) -> None:
    from ecs_tentacles.render.gui import set_ui_scale

    heights = []
    for factor in (1.0, 1.5):
        set_ui_scale(factor)
        try:
            sandbox = make_sandbox("octopus", width=1280, height=720)
            sandbox.render()
            rect = sandbox.hud.gui.rects["speed label"]
            heights.append(rect[3] - rect[1])
        finally:
            set_ui_scale(1.0)
    assert heights[1] > 1.3 * heights[0]


def test_at_720p_every_section_fits_the_panel(make_sandbox: Callable[..., Any]) -> None:
    """At 1280 x 720 the panel leaves the view at least 78 % of the width, its text at
    scale 1, and no section's widget runs past the panel's edges (each opened in turn)."""
    sandbox = make_sandbox("hedgehog_octopus", width=1280, height=720)  # fur: every section
    sandbox.render()
    gui = sandbox.hud.gui
    x0, _, x1, _ = gui.windows["panel"]
    assert x1 - x0 == PANEL_WIDTH <= 0.22 * 1280 and gui.scale == 1.0
    sections = ["Stats", "Physics", "Plugins", "Locomotion", "Fur", "View", "Director"]
    sections += ["Terrain", "Actions"]
    for name in sections:
        sandbox.hud.unfold(name)
        sandbox.render()
        left, _, right, _ = gui.clips["panel"]  # where the panel's widgets show unclipped
        mine = {n: r for n, r in gui.rects.items() if x0 <= r[0] < x1}  # not the timeline's
        below = [mine[s][1] for s in sections if mine[s][1] > mine[name][3]]
        end = min(below, default=float("inf"))  # the next header's top
        inside = [n for n, r in mine.items() if mine[name][3] <= r[1] < end]
        assert len(inside) >= 2, name  # the section is open: its widgets between the headers
        assert [n for n, r in mine.items() if r[2] > right or r[0] < left] == [], name
