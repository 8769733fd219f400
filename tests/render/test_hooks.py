"""The sandbox's registries: a user's plugin draws, adds a HUD section and takes clicks
(entries added in its `build(app)`); an old-style render hook is refused by name; every
entry belongs to a plugin that is on; the sandbox runs with the fur and locomotion
plugins off."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from pyglet.window import mouse

from tests.render.conftest import event

BEACON = '''
"""A user's plugin that draws through every registry of the sandbox."""
import numpy as np
from pyglet import gl

from ecs_tentacles.plugin import Plugin
from ecs_tentacles.render.registries import (
    Clicks, Draws, FramedPoints, Lines, Marker, Panel, Panels, Spheres,
)
from ecs_tentacles.render.rings import line_segments

SPHERE = (0.0, -1.0, 0.3)
LINE = ((-1.5, 1.0, 0.02), (1.5, 1.0, 0.02))
FAR = (4.0, 4.0, 0.0)


class BeaconPanel(Panel):
    title = "Beacon"

    def draw(self, gui):
        from imgui_bundle import imgui

        imgui.text("beacon on")
        gui.item("beacon text")


class BeaconPlugin(Plugin):
    name = "beacon"

    def __init__(self, config=None):
        super().__init__(config)
        self.clicks = []

    def build(self, app):
        app.add(Spheres, self.spheres)
        app.add(Lines, self.lines)
        app.add(Draws, self.draw)
        app.add(FramedPoints, self.points)
        app.add(Panels, lambda sandbox: [BeaconPanel()])
        app.add(Clicks, self.click)

    def spheres(self, world):
        return [Marker(np.array([SPHERE]), (0.25, 0.25, 0.25), (1.0, 0.0, 1.0, 1.0))]

    def lines(self, world, view):
        return [line_segments(np.array(LINE), np.array([0.0, 1.0, 0.0, 1.0]))]

    def draw(self, world, view):
        view.state["beacon.frames"] = view.state.get("beacon.frames", 0) + 1
        gl.glEnable(gl.GL_SCISSOR_TEST)  # a cyan square in the bottom-left corner
        gl.glScissor(0, 0, 12, 12)
        gl.glClearColor(0.0, 1.0, 1.0, 1.0)
        gl.glClear(gl.GL_COLOR_BUFFER_BIT)
        gl.glDisable(gl.GL_SCISSOR_TEST)
        return 1

    def points(self, world):
        return np.array([FAR])

    def click(self, world, click):
        self.clicks.append(click)
        return True
'''


def _beacon_scene(tmp_path: Path) -> Path:
    (tmp_path / "beacon.py").write_text(BEACON)
    scene = {
        "version": 1,
        "plugins": {"beacon": {"from": "beacon.py"}},
        "creatures": [{"name": "octo", "tentacles": {"count": 6, "links": 6}}],
    }
    path = tmp_path / "beacon_scene.json"
    path.write_text(json.dumps(scene))
    return path


def _near(pixels: np.ndarray, x: float, y: float, rgb: tuple[int, int, int], reach: int) -> bool:
    """A pixel within `reach` of pyglet pixel (x, y) has about colour `rgb`."""
    row, col = pixels.shape[0] - round(y), round(x)
    patch = pixels[max(row - reach, 0) : row + reach + 1, max(col - reach, 0) : col + reach + 1]
    return bool((np.abs(patch.astype(int) - rgb).max(axis=2) < 40).any())


def test_a_user_plugin_draws_adds_a_panel_and_takes_clicks(
    make_sandbox: Callable[..., Any], tmp_path: Path
) -> None:
    sandbox = make_sandbox(_beacon_scene(tmp_path), allow_systems=True)
    beacon = next(p for p in sandbox.world.plugins if p.key == "beacon")
    module = __import__(type(beacon).__module__, fromlist=["SPHERE"])
    camera = sandbox.renderer.camera
    x, y = camera.project(np.array([module.FAR]))[0]  # "frame all" kept it in view
    assert sandbox.hud.width < x < 640 and 0 < y < 360

    sandbox.step(2)
    sandbox.hud.unfold("Beacon")
    sandbox.render()
    assert {"Beacon", "beacon text"} <= set(sandbox.hud.gui.rects)  # its HUD section
    sandbox.hud.visible = False
    calls = sandbox.renderer.draw()
    assert calls == 10 + 1  # the renderer's own (skinned view, the sky) and the plugin's
    pixels = sandbox.renderer.target.read()
    assert tuple(pixels[-3, 3]) == (0, 255, 255)  # its own GL drawing, bottom left
    sx, sy = camera.project(np.array([module.SPHERE]))[0]
    r, g, b = pixels[360 - round(sy), round(sx)].astype(int)
    assert r > g + 80 and b > g + 80  # the magenta sphere, lit
    middle = np.mean(module.LINE, axis=0)
    lx, ly = camera.project(middle[None])[0]
    assert _near(pixels, lx, ly, (0, 255, 0), reach=2)  # the green line
    assert sandbox.renderer.state["beacon.frames"] >= 2  # kept across frames

    ground = np.array([-1.5, -1.5, 0.0])  # no goal there: locomotion leaves it alone
    gx, gy = camera.project(ground[None])[0]
    event(sandbox, "on_mouse_press", round(gx), round(gy), mouse.RIGHT, 0)
    event(sandbox, "on_mouse_release", round(gx), round(gy), mouse.RIGHT, 0)
    (click,) = beacon.clicks
    assert click.button == "right" and click.creature is None
    assert np.linalg.norm(click.ground - ground) < 0.02
    assert click.selected == sandbox.world.creature("octo")


def test_the_sandbox_runs_with_fur_and_locomotion_off(
    make_sandbox: Callable[..., Any], tmp_path: Path
) -> None:
    off = {"locomotion": False, "suckers": False, "fur": False}
    scene = {"version": 1, "plugins": off, "creatures": [{"name": "still"}]}
    sandbox = make_sandbox(scene)
    plugins = [p.key for p in sandbox.world.plugins]
    assert plugins == ["threats", "clips", "terrain", "render", "director"]  # the sandbox adds two
    x, y = sandbox.renderer.camera.project(np.array([[1.0, 0.5, 0.0]]))[0]
    for button in (mouse.LEFT, mouse.RIGHT):  # clicks nobody takes do nothing
        event(sandbox, "on_mouse_press", round(x), round(y), button, 0)
        event(sandbox, "on_mouse_release", round(x), round(y), button, 0)
    result = sandbox.run_headless(5, screenshot=tmp_path / "off.png", progress=False)
    assert Path(result["screenshot"]).stat().st_size > 1000
    rects = sandbox.hud.gui.rects
    assert {"Stats", "Physics", "Plugins"} <= set(rects)
    assert not {"Locomotion", "Actions", "Fur"} & set(rects)
    # ground, shadows, 4 meshes, sucker discs, skinned, lines
    assert sandbox.renderer.draw_calls == 10
    pixels = sandbox.renderer.target.read().astype(int)
    top = sandbox.world.transforms.pos[sandbox.renderer.mantle_rows[0]]
    mx, my = sandbox.renderer.camera.project(top[None])[0]
    r, g, b = pixels[360 - round(my), round(mx)]
    assert r > g + 60 and r > b + 60  # the creature is drawn


def test_an_old_style_render_hook_is_refused_by_name() -> None:
    import pytest

    from ecs_tentacles.plugin import Plugin

    with pytest.raises(TypeError, match=r"Old\.render_lines: this hook is now a Lines entry"):
        type("Old", (Plugin,), {"render_lines": lambda self, world, view: []})


def test_every_registry_entry_belongs_to_a_plugin_that_is_on(
    make_sandbox: Callable[..., Any], tmp_path: Path
) -> None:
    """Walk every registry the sandbox's world has (every built-in plugin that draws,
    adds a panel, takes clicks or keeps undo state, and a user's), before and after a
    rebuild without one of them."""
    from ecs_tentacles.render.registries import (
        Clicks,
        Draws,
        FramedPoints,
        Lines,
        OverlayLines,
        OverlaySpheres,
        Panels,
        Spheres,
        UndoStates,
    )

    sandbox = make_sandbox(_beacon_scene(tmp_path), allow_systems=True)

    def owners() -> dict[str, set[str]]:
        world = sandbox.world
        on = {plugin.key for plugin in world.plugins}
        found = {}
        for kind, registry in world.registries.all().items():
            keys = {owner for owner, _ in registry.items()}
            assert keys <= on, (kind.__name__, keys - on)
            found[kind.__name__] = keys
        return found

    seen = owners()
    kinds = {Spheres, Lines, OverlaySpheres, OverlayLines, Draws, FramedPoints, Panels, Clicks}
    kinds.add(UndoStates)
    assert {k.__name__ for k in kinds} <= set(seen)
    assert "beacon" in seen["Clicks"] and "locomotion" in seen["Clicks"]
    assert {"threats", "beacon"} <= seen["Spheres"]
    assert {"render", "suckers"} <= seen["OverlaySpheres"]  # the editor's: tiers, suckers
    assert "locomotion" in seen["OverlayLines"]  # goal rings and paths
    assert "locomotion" in seen["UndoStates"]
    scene = json.loads((tmp_path / "beacon_scene.json").read_text())
    scene["plugins"]["threats"] = False
    sandbox.rebuild(scene)
    assert "threats" not in owners()["Spheres"]
