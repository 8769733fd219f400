"""Blob shadows, sucker discs and a ground that reads as ground: the sandbox's polish,
seen in the pixels of headless renders and in the instance rows."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

from ecs_tentacles.ground import FLAT
from ecs_tentacles.render.decals import SHADOW_ALPHA, shadow_instances, sucker_instances
from ecs_tentacles.terrain.ground import TerrainGround
from ecs_tentacles.terrain.heightfield import Heightfield

UP = np.array([0.0, 0.0, 1.0])


def test_a_blob_lies_on_the_ground_under_its_body_and_fades_as_it_rises() -> None:
    centres = np.array([[1.0, 2.0, 0.03], [1.0, 2.0, 0.6]])
    rows = shadow_instances(FLAT, centres, np.array([0.03, 0.03]), UP)
    assert rows[:, 0:2].tolist() == [[1.0, 2.0], [1.0, 2.0]]  # a light from above: under it
    assert rows[0, 14] == pytest.approx(SHADOW_ALPHA) and rows[1, 14] == 0.0  # gone up high
    hill = TerrainGround(Heightfield((4.0, 4.0), np.full((3, 3), 0.5)))
    on_hill = shadow_instances(hill, np.array([[0.0, 0.0, 0.53]]), np.array([0.03]), UP)
    assert on_hill[0, 2] == pytest.approx(0.504)  # on the terrain, not at z = 0


def test_sucker_discs_sit_on_their_links_and_darken_when_gripping() -> None:
    pos = np.array([[0.0, 0.0, 0.1]])
    quat = np.array([[1.0, 0.0, 0.0, 0.0]])
    rows = sucker_instances(
        pos, quat, np.array([0, 0]), np.array([[0.03, 0, -0.02]] * 2), np.array([0.02, 0.02]),
        np.array([False, True]),
    )  # fmt: skip
    np.testing.assert_allclose(rows[:, 0:3], [[0.03, 0.0, 0.08]] * 2, atol=1e-7)
    assert rows[0, 11:14].sum() > rows[1, 11:14].sum() + 0.5  # pale free, dark gripping


def test_the_ground_is_warm_and_shadows_darken_it_only_under_creatures(
    make_sandbox: Callable[..., Any],
) -> None:
    sandbox = make_sandbox("octopus")
    sandbox.hud.visible = False
    sandbox.step(30)
    renderer = sandbox.renderer
    renderer.draw()
    lit = renderer.target.read().astype(int)
    assert renderer.shadows.count == len(renderer.shadow_rows) > len(renderer.mantle_rows)
    assert renderer.sucker_discs.count == len(sandbox.world.suckers)
    r, _, b = lit[8, 8]  # a corner of open ground
    assert r > b + 20  # sand, not the grey-green of a grid floor
    renderer.shadows.update(np.zeros((0, 15), np.float32))
    renderer._fill = lambda pos, quat: None  # draw again as is, without the blobs
    renderer.draw()
    bare = renderer.target.read().astype(int)
    darker = lit.sum(axis=2) < bare.sum(axis=2) - 6
    assert darker.sum() > 200  # the blobs show
    rows, cols = np.nonzero(darker)
    camera = renderer.camera
    mantle = sandbox.world.transforms.pos[renderer.mantle_rows[0]]
    x, y = camera.project(mantle[None])[0]
    pixels = np.hypot(cols - x, (camera.height - rows) - y)
    assert np.percentile(pixels, 95) < 0.25 * camera.width  # around the creature only
