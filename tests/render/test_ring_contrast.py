"""Rings stand out on any ground: a ring in a muted creature colour, drawn on sand and
on grey rock, differs from the ground under it by a clear margin (pixels read back)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

from ecs_tentacles.ground import ground_of
from ecs_tentacles.render.camera import CameraChoice
from ecs_tentacles.render.rings import CIRCLE
from ecs_tentacles.skin.colours import Look, creature_colour

ROCK = {"shape": "box", "position": [1.0, 1.0, 0.3], "size": [1.4, 1.4, 0.6]}
SAND = (-1.2, -1.0)
HILLS = {"size": [8, 8], "resolution": 33, "height": 0.15, "noise": {"seed": 2}}
CONTRAST = 60.0  # luminance (0-255) the ring's pixels differ from the bare ground by


def _luminance(pixels: np.ndarray) -> np.ndarray:
    return pixels[..., :3].astype(float) @ [0.2126, 0.7152, 0.0722]


def _ring(centre: np.ndarray, radius: float, rgba: tuple[float, ...]) -> np.ndarray:
    points = centre + radius * CIRCLE
    pairs = np.stack([points[:-1], points[1:]], axis=1).reshape(-1, 3)
    return np.hstack([pairs, np.tile(rgba, (len(pairs), 1))])


def test_a_ring_stands_out_on_sand_and_on_rock(make_sandbox: Callable[..., Any]) -> None:
    scene = {
        "version": 1,
        "terrain": {"heightfield": HILLS, "obstacles": [ROCK]},
        "creatures": [{"name": "octo", "position": [2.5, -2.5]}],
    }
    sandbox = make_sandbox(scene, hud=False)
    sandbox.select(None)
    sandbox.aim(CameraChoice("fixed", eye=(-3.0, -6.0, 4.0), target=(0.0, 0.0, 0.2)))
    ground = ground_of(sandbox.world)
    sand = np.array([*SAND, ground.height(np.array([SAND]))[0] + 0.01])
    rock = np.array([1.0, 1.0, 0.6 + ground.height(np.array([[1.0, 1.0]]))[0] + 0.01])
    colour = (*creature_colour(Look("octo", 0, (8, *[6] * 8, 150))), 1.0)  # muted rose
    renderer = sandbox.renderer
    sandbox.render()
    bare = _luminance(renderer.target.read())
    renderer.extra_lines.append(
        lambda world: np.vstack([_ring(sand, 0.5, colour), _ring(rock, 0.5, colour)])
    )
    sandbox.render()
    drawn = _luminance(renderer.target.read())
    height = bare.shape[0]
    for where in (sand, rock):
        ring = where + 0.5 * CIRCLE
        pixels = renderer.camera.project(ring)
        x0, y0 = np.floor(pixels.min(axis=0)).astype(int) - 4
        x1, y1 = np.ceil(pixels.max(axis=0)).astype(int) + 4
        rows = slice(height - y1, height - y0)
        change = drawn[rows, x0:x1] - bare[rows, x0:x1]
        changed = np.abs(change) > 8
        assert changed.sum() > 40, where  # the ring is drawn there
        # its dark edge is far darker than the ground, whatever the ground (a ring in
        # the creature's own colour was 29 darker than sand: hard to see)
        assert np.percentile(change[changed], 10) < -CONTRAST, where
        assert np.percentile(np.abs(change[changed]), 90) > 1.5 * CONTRAST, where


@pytest.mark.parametrize("scene", ["rocky_shore", "ramp"])  # 0.7 m of hills; a platform
def test_goal_and_selection_rings_follow_the_ground_and_what_stands_on_it(
    make_sandbox: Callable[..., Any], scene: str
) -> None:
    sandbox = make_sandbox(scene)
    world = sandbox.world
    ground = ground_of(world)
    sandbox.select_many(sandbox.renderer.creature_entities)
    lines = sandbox.renderer._line_vertices(world.transforms.pos).astype(np.float64)
    assert len(lines) > 100
    above = lines[:, 2] - ground.surface(lines[:, :2])  # the ground, or a solid's top
    # rings lie 5-10 mm over the surface under every vertex; before, a ring kept its
    # centre's height and sank into a slope, or lay on the ground inside a platform
    near_surface = np.abs(above) < 0.05
    assert near_surface.mean() > 0.8  # the rings (goal posts and legs rise above them)
    assert (above[near_surface] > 0.0).all()
