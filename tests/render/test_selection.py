"""Selecting many creatures in the sandbox (headless, by pyglet events) and sending them."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from pyglet.window import key, mouse

from ecs_tentacles.components import Transform
from ecs_tentacles.locomotion.formations import FormationChoice, reach
from ecs_tentacles.locomotion.goals import GoalBook
from ecs_tentacles.locomotion.params import Locomotion

from .conftest import click_at, click_gui, event, pixel


def _mantle(sandbox: Any, name: str) -> Any:
    world = sandbox.world
    return world.component(world.creature(name), Transform).pos.copy()


def _crowd(count: int) -> dict[str, Any]:
    creatures = [
        {"name": f"c{i}", "position": [2.0 * (i % 4), 2.0 * (i // 4)],
         "tentacles": {"count": 5, "links": 6}}
        for i in range(count)
    ]  # fmt: skip
    return {"version": 1, "creatures": creatures}


def _band(sandbox: Any, first: str, last: str, modifiers: int = 0) -> None:
    """Left-drag a rectangle round the mantles of creatures `first` and `last`."""
    low = np.array(pixel(sandbox, _mantle(sandbox, first)))
    high = np.array(pixel(sandbox, _mantle(sandbox, last)))
    corner = np.minimum(low, high) - 12
    other = np.maximum(low, high) + 12
    event(sandbox, "on_mouse_press", *corner.tolist(), mouse.LEFT, modifiers)
    event(sandbox, "on_mouse_drag", *other.tolist(), 5, 5, mouse.LEFT, modifiers)
    assert sandbox.hud.band is not None  # the rubber band is drawn while dragging
    sandbox.render()
    event(sandbox, "on_mouse_release", *other.tolist(), mouse.LEFT, modifiers)
    assert sandbox.hud.band is None


def test_a_drag_selects_the_creatures_in_the_rectangle(make_sandbox: Callable[..., Any]):
    sandbox = make_sandbox(_crowd(8))
    camera = sandbox.renderer.camera
    camera.pitch, camera.yaw = camera.MAX_PITCH, -np.pi / 2  # from above, rows across
    view = (camera.pitch, camera.yaw, camera.distance)
    world = sandbox.world
    _band(sandbox, "c4", "c5")  # a rectangle round c4 and c5 only
    names = sorted(world.creature_name(e) for e in sandbox.selection.entities)
    assert names == ["c4", "c5"]
    assert (camera.pitch, camera.yaw, camera.distance) == view  # the camera stays
    _band(sandbox, "c0", "c3")  # a new rectangle: the first row instead
    names = sorted(world.creature_name(e) for e in sandbox.selection.entities)
    assert names == ["c0", "c1", "c2", "c3"]
    _band(sandbox, "c4", "c4", key.MOD_SHIFT)  # shift-drag adds
    names = sorted(world.creature_name(e) for e in sandbox.selection.entities)
    assert names == ["c0", "c1", "c2", "c3", "c4"]
    _band(sandbox, "c4", "c4")
    _band(sandbox, "c0", "c3", key.MOD_SHIFT)
    names = sorted(world.creature_name(e) for e in sandbox.selection.entities)
    assert names == ["c0", "c1", "c2", "c3", "c4"]
    assert set(sandbox.renderer.selection) == set(sandbox.selection.entities)
    _band(sandbox, "c0", "c3")
    # shift-click takes one out and puts another in
    click_at(sandbox, pixel(sandbox, _mantle(sandbox, "c1")), key.MOD_SHIFT)
    click_at(sandbox, pixel(sandbox, _mantle(sandbox, "c5")), key.MOD_SHIFT)
    names = sorted(world.creature_name(e) for e in sandbox.selection.entities)
    assert names == ["c0", "c2", "c3", "c5"]
    assert sandbox.renderer.selected == world.creature("c5")  # the last picked: the HUD's
    # Ctrl+A: everyone; Esc: no one, and the window stays open
    event(sandbox, "on_key_press", key.A, key.MOD_CTRL)
    assert len(sandbox.selection) == 8
    event(sandbox, "on_key_press", key.ESCAPE, 0)
    assert len(sandbox.selection) == 0 and sandbox.renderer.selected is None
    assert not sandbox.window.has_exit
    # the level of detail runs every selected creature at full physics
    event(sandbox, "on_key_press", key.A, key.MOD_CTRL)
    sandbox.step(1)
    assert world.lod.selected.all()


def test_a_click_sends_the_selection_in_formation(make_sandbox: Callable[..., Any]):
    sandbox = make_sandbox(_crowd(8))
    world = sandbox.world
    book = world.resource(GoalBook)
    chosen = [world.creature(f"c{i}") for i in (0, 1, 2, 5, 6)]
    point = np.array([3.0, 9.0, 0.0])
    for shape in ("ring", "grid", "line"):
        sandbox.select_many(chosen)
        world.resource(FormationChoice).shape = shape
        click_at(sandbox, pixel(sandbox, point))
        goals = np.array([book.positions(c)[0] for c in chosen])
        assert all(len(book.path(c)) == 1 for c in chosen)  # one goal each, none shared
        gap = np.linalg.norm(goals[:, None, :2] - goals[None, :, :2], axis=2)
        np.fill_diagonal(gap, np.inf)
        reaches = np.array([reach(world, c) for c in chosen])
        assert (gap >= reaches[:, None] + reaches[None, :]).all(), shape  # no overlap
        assert np.linalg.norm(goals[:, :2].mean(axis=0) - point[:2]) < 2 * reaches.max()
    # shift-click: a waypoint appended to every selected creature's path
    click_at(sandbox, pixel(sandbox, [-4.0, 9.0, 0.0]), key.MOD_SHIFT)
    assert [len(book.path(c)) for c in chosen] == [2] * 5
    assert all(len(book.path(world.creature(n))) == 0 for n in ("c3", "c4", "c7"))


def test_the_sliders_move_every_selected_creature(make_sandbox: Callable[..., Any]):
    sandbox = make_sandbox(_crowd(4))
    world = sandbox.world
    chosen = [world.creature(n) for n in ("c0", "c2", "c3")]
    sandbox.select_many(chosen)
    sandbox.render()
    x0, y0, x1, y1 = sandbox.hud.gui.rects["speed"]
    click_gui(sandbox, x0 + 0.8 * (x1 - x0), (y0 + y1) / 2)
    api = world.resource(Locomotion)
    speeds = [api.get(c, 0)["creature_speed"] for c in chosen]
    assert speeds[0] != 1.0 and speeds == [speeds[0]] * 3
    assert api.get(world.creature("c1"), 0)["creature_speed"] == 1.0  # not selected
    assert {"formation ring", "formation grid", "formation line"} <= set(sandbox.hud.gui.rects)
