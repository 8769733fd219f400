"""Rendering hooks: guide polylines with colour and width, child hairs, controls."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from ecs_tentacles.fur import child_hairs, control_markers, guide_curves
from ecs_tentacles.fur.stores import FurData
from ecs_tentacles.numeric.quaternions import quat_rotate
from ecs_tentacles.world import World
from tests.conftest import NO_LOCOMOTION

SCENE = {
    "version": 1,
    "creatures": [
        {
            "name": "c",
            "tentacles": {"count": 3, "links": 2},
            "fur": {
                "groom": {"count": 40, "points": 6},
                "colour": [0.2, 0.4, 0.6],
                "width": 0.004,
                "children": 3,
                "controls": [{"name": "a", "colour": [1, 0, 0], "shape": "cube"}],
            },
        }
    ],
    "threats": [{"name": "roach", "path": [{"time": 0, "position": [1, 2, 3]}]}],
}


def test_guide_curves(make_world: Callable[..., World]) -> None:
    world = make_world(SCENE, plugins=NO_LOCOMOTION)
    world.step(1)
    curves = guide_curves(world)
    assert curves.points.shape == (40, 6, 3) and curves.points.dtype == np.float32
    assert_array_equal(curves.points, world.resource(FurData).curves)
    assert curves.points is not world.resource(FurData).curves
    assert_allclose(curves.colour, np.tile([0.2, 0.4, 0.6, 1.0], (40, 1)), atol=1e-7)
    assert_allclose(curves.width, 0.004, atol=1e-9)
    by_control = guide_curves(world, colour_by="control")
    assert_allclose(by_control.colour[:, :3], np.tile([1, 0, 0], (40, 1)))
    with pytest.raises(ValueError, match="colour_by must be 'fur' or 'control', got 'x'"):
        guide_curves(world, colour_by="x")


def test_child_hairs_follow_their_guide(make_world: Callable[..., World]) -> None:
    world = make_world(SCENE, plugins=NO_LOCOMOTION)
    world.step(1)
    kids = child_hairs(world, radius=0.01, seed=2, follow="own")
    assert kids.points.shape == (120, 6, 3)
    assert_array_equal(kids.guide, np.repeat(np.arange(40), 3))
    parent = world.resource(FurData).curves[kids.guide]
    offset = kids.points[:, 0] - parent[:, 0]
    assert np.linalg.norm(offset, axis=1).max() <= 0.01 + 1e-6
    g = world.resource(FurData).guides
    normal = quat_rotate(world.transforms.quat[g.body_row[kids.guide]], g.normal[kids.guide])
    assert_allclose(np.sum(offset * normal, axis=1), 0.0, atol=1e-6)  # in the tangent plane
    shape = kids.points - kids.points[:, :1]
    parent_shape = parent - parent[:, :1]
    scale = np.linalg.norm(shape[:, -1], axis=1) / np.linalg.norm(parent_shape[:, -1], axis=1)
    assert np.all((scale > 0.7 - 1e-5) & (scale < 1.0 + 1e-5))
    assert_allclose(shape, scale[:, None, None] * parent_shape, atol=1e-6)
    assert child_hairs(world, per_guide=0, follow="own").points.shape == (0, 6, 3)
    again = child_hairs(world, seed=2, follow="own").points
    assert_array_equal(child_hairs(world, seed=2, follow="own").points, again)


@pytest.mark.parametrize("follow", ["neighbours", "own"])
def test_child_hairs_of_some_guides_are_those_children_as_among_all(
    make_world: Callable[..., World], follow: str
) -> None:
    world = make_world(SCENE, plugins=NO_LOCOMOTION)
    world.step(1)
    every = child_hairs(world, follow=follow, points=3)
    guides = np.arange(40) % 3 == 0  # the sandbox leaves out the guides seen too short
    some = child_hairs(world, follow=follow, points=3, guides=guides)
    kept = guides[every.guide]
    assert kept.sum() == 14 * 3 and len(some.guide) == kept.sum()
    for field in ("points", "colour", "width", "guide"):
        assert_array_equal(getattr(some, field), getattr(every, field)[kept])
    none = child_hairs(world, follow=follow, guides=np.zeros(40, dtype=bool))
    assert none.points.shape == (0, 6, 3)


def test_controls(make_world: Callable[..., World]) -> None:
    world = make_world(SCENE, plugins=NO_LOCOMOTION)
    world.step(1)
    (marker,) = control_markers(world)
    mantle = world.transforms.pos[world.resource(FurData).sets.body_row[0]]
    quat = world.transforms.quat[world.resource(FurData).sets.body_row[0]]
    assert (marker.name, marker.shape) == ("a", "cube")
    assert_allclose(marker.position, mantle + quat_rotate(quat, np.array([0, 0, 0.3])))


def test_a_world_without_fur_gives_empty_arrays(make_world: Callable[..., World]) -> None:
    world = make_world({"version": 1, "creatures": [{"tentacles": {"count": 3, "links": 2}}]})
    world.step(1)
    assert guide_curves(world).points.shape[0] == 0
    assert child_hairs(world).points.shape[0] == 0
    assert control_markers(world) == []
