"""The sandbox on terrain: the heightfield and obstacles are drawn as lit solids in two
draws, and a click lands on what is under the cursor (an obstacle's top, a hill)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from pyglet.window import mouse

from ecs_tentacles.locomotion.goals import GoalBook
from tests.render.conftest import event

TABLE = {"shape": "box", "position": [1.0, 1.4, 0.25], "size": [0.8, 0.8, 0.5]}
HILLS = {"size": [8, 8], "resolution": 33, "height": 0.4, "noise": {"seed": 1}}


def terrain_scene() -> dict[str, Any]:
    return {
        "version": 1,
        "terrain": {"heightfield": HILLS, "obstacles": [TABLE]},
        "creatures": [
            {"name": "octo", "position": [-0.5, 0], "goals": [{"position": [0.8, -1.2]}]}
        ],
    }


def test_terrain_and_obstacles_are_drawn_and_clicks_land_on_them(
    make_sandbox: Callable[..., Any],
) -> None:
    sandbox = make_sandbox(terrain_scene())
    sandbox.hud.visible = False
    camera = sandbox.renderer.camera
    top = np.array([[1.0, 1.4, 0.5 + _hill_height(sandbox, 1.0, 1.4)]])  # the table's top
    camera.shift_x = 0.0
    camera.fit(np.vstack([top, [[-1.0, -1.2, 0.0], [-0.5, 0.0, 0.0]]]), border=0.2)
    calls = sandbox.renderer.draw()
    # the grid's draw gives way to the terrain's, the ground beyond it and the obstacles'
    assert calls == 10 + 2
    pixels = sandbox.renderer.target.read().astype(int)
    tx, ty = camera.project(top)[0]
    r, g, b = pixels[camera.height - round(ty), round(tx)]
    assert abs(r - g) < 25 and abs(g - b) < 25  # grey rock, not sky or sand
    r, g, b = pixels[camera.height - 8, camera.width // 2]  # bottom middle: the hills
    assert r > b + 30  # sand, lit (the plane's grid would be grey-green)

    octo = sandbox.world.creature("octo")
    sandbox.select(octo)
    book = sandbox.world.resource(GoalBook)
    for x, y in (top[0, :2], (-1.0, -1.2)):
        point = np.array([[x, y, 0.0]])
        point[0, 2] = top[0, 2] if x == top[0, 0] else _hill_height(sandbox, x, y)
        px, py = camera.project(point)[0]
        event(sandbox, "on_mouse_press", round(px), round(py), mouse.LEFT, 0)
        event(sandbox, "on_mouse_release", round(px), round(py), mouse.LEFT, 0)
        goal = book.positions(octo)[0]
        assert np.linalg.norm(goal[:2] - point[0, :2]) < 0.05
        assert abs(goal[2] - point[0, 2]) < 0.02  # on what was clicked, not at z = 0


def _hill_height(sandbox: Any, x: float, y: float) -> float:
    from ecs_tentacles.ground import ground_of

    return float(ground_of(sandbox.world).height(np.array([[x, y]]))[0])


def test_the_terrain_section_places_moves_and_deletes_with_the_mouse(
    make_sandbox: Callable[..., Any],
) -> None:
    from ecs_tentacles.terrain.panel import TerrainPanel

    sandbox = make_sandbox(
        {"version": 1, "terrain": {"heightfield": HILLS}, "creatures": [{"name": "octo"}]}
    )
    sandbox.hud.visible = False
    assert sandbox.renderer.draw() == 11  # the terrain and beyond for the grid, no obstacles
    panel = next(p for p in sandbox.hud.panels if isinstance(p, TerrainPanel))
    camera = sandbox.renderer.camera
    spot = np.array([[1.5, -1.2, _hill_height(sandbox, 1.5, -1.2)]])
    camera.target, camera.distance = spot[0].copy(), 6.0  # the spot in the picture
    px, py = (round(v) for v in camera.project(spot)[0])
    assert 0 <= px < camera.width and 0 <= py < camera.height

    panel.tool = "box"
    event(sandbox, "on_mouse_press", px, py, mouse.LEFT, 0)
    event(sandbox, "on_mouse_release", px, py, mouse.LEFT, 0)
    (box,) = sandbox.world.scene["terrain"]["obstacles"]
    assert np.linalg.norm(np.array(box["position"][:2]) - spot[0, :2]) < 0.05
    assert sandbox.renderer.draw() == 12  # and the obstacles
    assert panel.message == "placed"

    panel.tool = "delete"
    top = np.array([[1.5, -1.2, box["position"][2] + box["size"][2] / 2]])
    tx, ty = (round(v) for v in camera.project(top)[0])
    event(sandbox, "on_mouse_press", tx, ty, mouse.LEFT, 0)
    event(sandbox, "on_mouse_release", tx, ty, mouse.LEFT, 0)
    assert sandbox.world.scene["terrain"]["obstacles"] == []
    assert sandbox.renderer.draw() == 11

    panel.tool = "raise"
    before = _hill_height(sandbox, 1.5, -1.2)
    event(sandbox, "on_mouse_press", px, py, mouse.LEFT, 0)
    event(sandbox, "on_mouse_release", px, py, mouse.LEFT, 0)
    assert _hill_height(sandbox, 1.5, -1.2) > before + 0.5 * panel.strength
    sandbox.step(5)  # the world goes on
    assert sandbox.world.physics.health.recoveries == 0
