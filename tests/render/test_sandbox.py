"""The sandbox drawn off-screen: pixels, clicks, HUD, draw calls, files."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from numpy.testing import assert_allclose
from PIL import Image
from pyglet.event import EventDispatcher
from pyglet.window import key, mouse

from ecs_tentacles.components import Creature, Transform
from ecs_tentacles.locomotion.components import Goal
from ecs_tentacles.locomotion.goals import GoalBook


def _event(sandbox: Any, name: str, *args: Any) -> None:
    """Deliver a window event now (a window queues events outside its own loop)."""
    EventDispatcher.dispatch_event(sandbox.window, name, *args)


def _click(sandbox: Any, x: float, y: float, button: int = mouse.LEFT, modifiers: int = 0) -> None:
    _event(sandbox, "on_mouse_press", round(x), round(y), button, modifiers)
    _event(sandbox, "on_mouse_release", round(x), round(y), button, modifiers)


def test_octopus_is_drawn_where_the_camera_says(make_sandbox: Callable[..., Any]) -> None:
    sandbox = make_sandbox("octopus")
    sandbox.step(30)
    sandbox.hud.visible = False
    sandbox.render()
    pixels = sandbox.renderer.target.read().astype(int)
    assert pixels.shape == (360, 640, 3)
    octo = sandbox.world.creature("octopus")
    creature = sandbox.world.component(octo, Creature)
    mantle = sandbox.world.component(octo, Transform).pos
    top = mantle + [0.0, 0.0, creature.mantle_height / 2]
    x, y = sandbox.renderer.camera.project(top[None])[0]
    r, g, b = pixels[360 - round(y), round(x)]
    assert r > g + 60 and r > b + 60  # the mantle's warm red, lit
    corner = pixels[5, 630]  # far ground in the top-right corner: grey-green, not red
    assert abs(corner[0] - corner[1]) < 25 and corner[1] > corner[2] - 25
    assert not (pixels == pixels[0, 0]).all()  # not a blank frame
    assert pixels.mean() > 60  # not a black frame


def test_clicks_set_append_and_remove_goals(make_sandbox: Callable[..., Any]) -> None:
    sandbox = make_sandbox("octopus")
    octo = sandbox.world.creature("octopus")
    camera = sandbox.renderer.camera
    first, second = np.array([0.8, -0.6, 0.0]), np.array([1.2, 0.5, 0.0])
    _click(sandbox, *camera.project(first[None])[0])
    path = sandbox.world.resource(GoalBook).path(octo)
    assert len(path) == 1
    assert np.linalg.norm(sandbox.world.component(path[0], Goal).position - first) < 0.01
    _click(sandbox, *camera.project(second[None])[0], modifiers=key.MOD_SHIFT)
    positions = sandbox.world.resource(GoalBook).positions(octo)
    assert positions.shape == (2, 3)
    assert np.linalg.norm(positions - [first, second], axis=1).max() < 0.01
    _click(sandbox, *camera.project(first[None])[0], button=mouse.RIGHT)
    assert_allclose(sandbox.world.resource(GoalBook).positions(octo), [second], atol=0.01)


def test_clicking_a_creature_selects_it(make_sandbox: Callable[..., Any]) -> None:
    sandbox = make_sandbox("thesis_four_by_six")
    world = sandbox.world
    target = world.creature("creature_2")
    centre = world.component(target, Transform).pos
    _click(sandbox, *sandbox.renderer.camera.project(centre[None])[0])
    assert sandbox.renderer.selected == target
    assert sandbox.hud.title == "creature_2"


def _crowd(count: int) -> dict[str, Any]:
    creatures = [
        {
            "name": f"c{i}",
            "position": [1.5 * (i % 4), 1.5 * (i // 4)],
            "tentacles": {"count": 5, "links": 6},
            "goals": [{"position": [1.5 * (i % 4) + 1.0, 1.5 * (i // 4)]}],
        }
        for i in range(count)
    ]
    return {"version": 1, "creatures": creatures}


def test_draw_calls_do_not_grow_with_creatures(make_sandbox: Callable[..., Any]) -> None:
    calls: dict[str, list[int]] = {"skinned": [], "capsules": []}
    for count in (1, 16):
        sandbox = make_sandbox(_crowd(count))
        sandbox.step(40)
        renderer = sandbox.renderer
        assert renderer.view == "skinned"  # the default
        calls["skinned"].append(renderer.draw())
        assert renderer.links_near.count + renderer.links_far.count == 0
        assert len(renderer.skinned.creatures) == count
        assert renderer.toggle_view() == "capsules"
        calls["capsules"].append(renderer.draw())
        assert renderer.links_near.count + renderer.links_far.count == count * 30
    # ground, mantles, near and far links, spheres, lines (+ all skinned creatures)
    assert calls == {"skinned": [10, 10], "capsules": [9, 9]}  # the sky's included


def test_headless_run_writes_a_screenshot_and_a_video(
    make_sandbox: Callable[..., Any], tmp_path: Path
) -> None:
    sandbox = make_sandbox("three_goals")
    result = sandbox.run_headless(
        12, screenshot=tmp_path / "shot.png", video=tmp_path / "clip.mp4", progress=False
    )
    assert result["frames"] == 12
    with Image.open(tmp_path / "shot.png") as image:
        assert image.size == (640, 360)
    assert (tmp_path / "clip.mp4").stat().st_size > 1000
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "clip.mp4",
        "shot.png",
    ]  # no partial files


def test_fur_and_threats_are_drawn(make_sandbox: Callable[..., Any]) -> None:
    from ecs_tentacles.fur.hooks import child_hairs, guide_curves
    from ecs_tentacles.fur.render.strands import strands_of

    sandbox = make_sandbox("hedgehog_octopus")
    sandbox.step(3)
    sandbox.render()
    world = sandbox.world
    guides, children = guide_curves(world).points, child_hairs(world).points
    assert guides.shape[0] == 500
    renderer = sandbox.renderer
    strands = strands_of(renderer.state)  # the fur plugin's GL objects, made by its hook
    assert strands.guides.count == 6 * guides.shape[0] * (guides.shape[1] - 1)
    assert strands.children.count == 6 * children.shape[0] * (children.shape[1] - 1)
    # ground, shadows, 4 meshes, sucker discs, skinned, lines, guides (no children)
    assert renderer.draw_calls == 11
    attached = int(world.suckers.attached.sum())
    assert sandbox.renderer.spheres.count == attached + 1  # the roach


def test_child_hairs_too_short_to_see_are_left_out(
    make_sandbox: Callable[..., Any], monkeypatch: pytest.MonkeyPatch
) -> None:
    from ecs_tentacles.fur.hooks import child_hairs
    from ecs_tentacles.fur.render import strands as module
    from ecs_tentacles.scene.load import bundled_scene

    scene = json.loads(bundled_scene("hedgehog_octopus").read_text())
    scene["creatures"][0]["fur"]["children"] = 4  # 2,000 child hairs round 500 guides
    sandbox = make_sandbox(scene, hud=False)
    sandbox.step(3)
    sandbox.render()
    strands = module.strands_of(sandbox.renderer.state)
    points = module.fur_display(sandbox.renderer.state).child_points
    every = child_hairs(sandbox.world, points=points).points
    assert every.shape[0] == 2000
    assert strands.children.count == 6 * every.shape[0] * (every.shape[1] - 1)  # close: all
    sandbox.renderer.camera.distance = 60.0  # the creature a few dozen pixels across
    sandbox.render()
    assert strands.children.count == 0 and strands.guides.count > 0
    far = sandbox.renderer.target.read().astype(int)
    monkeypatch.setattr(module, "CHILD_PIXELS", 0.0)  # the same view with every hair
    sandbox.render()
    assert strands.children.count > 0
    every_hair = sandbox.renderer.target.read().astype(int)
    changed = (np.abs(far - every_hair).sum(axis=2) > 30).sum()
    assert changed < 40, changed  # a few pixels of a 640 x 360 picture


def test_f5_saves_the_state_and_f9_goes_back(make_sandbox: Callable[..., Any]) -> None:
    sandbox = make_sandbox("octopus")
    _event(sandbox, "on_key_press", key.F9, 0)  # nothing saved yet: nothing happens
    sandbox.step(20)
    _event(sandbox, "on_key_press", key.F5, 0)
    saved = sandbox.world.transforms.pos.copy()
    sandbox.step(40)
    later = sandbox.world.transforms.pos.copy()
    assert not np.array_equal(saved, later)
    _event(sandbox, "on_key_press", key.F9, 0)
    assert sandbox.world.frame == 20
    assert np.array_equal(sandbox.world.transforms.pos, saved)
    sandbox.step(40)
    assert np.array_equal(sandbox.world.transforms.pos, later)  # the same 40 frames again


def test_right_drag_orbits_middle_drag_pans_and_a_shaky_click_stays_a_click(
    make_sandbox: Callable[..., Any],
) -> None:
    sandbox = make_sandbox("octopus")
    camera = sandbox.renderer.camera
    yaw, target = camera.yaw, camera.target.copy()
    x, y = sandbox.window.width * 3 // 4, sandbox.window.height // 3  # beside the HUD
    _event(sandbox, "on_mouse_press", x, y, mouse.RIGHT, 0)
    _event(sandbox, "on_mouse_drag", x + 40, y, 40, 0, mouse.RIGHT, 0)
    _event(sandbox, "on_mouse_release", x + 40, y, mouse.RIGHT, 0)
    assert camera.yaw != yaw and np.array_equal(camera.target, target)
    _event(sandbox, "on_mouse_press", x, y, mouse.MIDDLE, 0)
    _event(sandbox, "on_mouse_drag", x + 40, y, 40, 0, mouse.MIDDLE, 0)
    _event(sandbox, "on_mouse_release", x + 40, y, mouse.MIDDLE, 0)
    assert not np.array_equal(camera.target, target)
    # a click whose pointer shakes by a pixel or two sets a goal: no rubber band
    octo = sandbox.world.creature("octopus")
    sandbox.select_many([octo])
    ground = np.array([1.5, -1.0, 0.0])
    gx, gy = (round(float(v)) for v in camera.project(ground[None])[0])
    _event(sandbox, "on_mouse_press", gx, gy, mouse.LEFT, 0)
    _event(sandbox, "on_mouse_drag", gx + 2, gy + 1, 2, 1, mouse.LEFT, 0)
    assert sandbox.hud.band is None
    _event(sandbox, "on_mouse_release", gx + 2, gy + 1, mouse.LEFT, 0)
    goal = sandbox.world.resource(GoalBook).positions(octo)[-1]
    assert np.hypot(*(goal[:2] - ground[:2])) < 0.1
    assert sandbox.selection.entities == (octo,)


def test_a_goal_click_the_plugins_refuse_is_a_red_line_not_a_crash(
    make_sandbox: Callable[..., Any],
) -> None:
    from ecs_tentacles.locomotion.formations import FormationChoice
    from tests.render.conftest import click_at, pixel

    sandbox = make_sandbox("rocky_shore")
    sandbox.hud.visible = False
    sandbox.select_many(sandbox.renderer.creature_entities)
    sandbox.world.resource(FormationChoice).shape = "spiral"  # as a script might set it
    point = np.array([1.0, 0.5, 0.0])
    sandbox.renderer.camera.target = point.copy()
    click_at(sandbox, pixel(sandbox, point))
    ok, line = sandbox.scripts.notes[-1]
    assert not ok and line.startswith("click refused: formation: must be one of")
    sandbox.step(1)  # the sandbox goes on


def _run_until(sandbox: Any, leave: Callable[[], None], monkeypatch: pytest.MonkeyPatch) -> bool:
    """Run the sandbox's window loop, `leave()` called 0.3 s in; True when the loop
    ended by it (not by the 30 s fallback). (pyglet's loop switches its windows' event
    queue off for good, and a headless window made after that fails: put back after.)"""
    import pyglet

    monkeypatch.setattr(pyglet.window.Window, "_enable_event_queue", True)
    fallback = []
    pyglet.clock.schedule_once(lambda _dt: leave(), 0.3)
    pyglet.clock.schedule_once(lambda _dt: (fallback.append(1), pyglet.app.exit()), 30)
    try:
        sandbox.run()
    finally:
        pyglet.clock.unschedule(sandbox.tick)
    return not fallback


def test_ctrl_q_quits_the_window_loop(
    make_sandbox: Callable[..., Any], monkeypatch: pytest.MonkeyPatch
) -> None:
    sandbox = make_sandbox("octopus")
    ctrl_q = lambda: _event(sandbox, "on_key_press", key.Q, key.MOD_CTRL)  # noqa: E731
    assert _run_until(sandbox, ctrl_q, monkeypatch)
    assert sandbox.world.time > 0  # it ran frames before


def test_ctrl_c_in_the_terminal_quits_as_closing_does(
    make_sandbox: Callable[..., Any], monkeypatch: pytest.MonkeyPatch
) -> None:
    """SIGINT ends the loop cleanly (no KeyboardInterrupt), and the handler that was
    there before comes back."""
    import os
    import signal

    sandbox = make_sandbox("octopus")
    before = signal.getsignal(signal.SIGINT)
    assert _run_until(sandbox, lambda: os.kill(os.getpid(), signal.SIGINT), monkeypatch)
    assert signal.getsignal(signal.SIGINT) is before
