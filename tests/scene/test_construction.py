"""The thesis's construction rules (IV.A, z-up), against hand-computed numbers."""

from __future__ import annotations

from collections.abc import Callable

import mujoco
import numpy as np
import pytest
from numpy.testing import assert_allclose

from ecs_tentacles.components import Creature, Link, Tentacle, Transform
from ecs_tentacles.scene.construction import (
    capsule_mass_inertia,
    creature_layout,
    creature_reach,
    cylinder_mass_inertia,
    link_scales,
    tentacle_angles,
    tentacle_shape,
)
from ecs_tentacles.scene.defaults import with_defaults
from ecs_tentacles.world import World

S = np.sqrt(0.5)
H = np.sqrt(3) / 2


def test_one_link_is_the_first_link_at_full_scale() -> None:
    assert_allclose(link_scales(1, 0.3), [1.0])
    shape = tentacle_shape(0.2, 0.1, 0.02, 1, 0.3)
    assert_allclose(shape.lengths, [0.1])
    assert_allclose(shape.radii, [0.02])
    assert_allclose(shape.centres, [0.25])


def test_two_links() -> None:
    shape = tentacle_shape(0.2, 0.1, 0.02, 2, 0.5)
    assert_allclose(shape.scales, [1.0, 0.5])
    assert_allclose(shape.lengths, [0.1, 0.05])
    assert_allclose(shape.radii, [0.02, 0.01])
    assert_allclose(shape.centres, [0.25, 0.325])  # 0.25 + (0.1 + 0.05) / 2


def test_ten_links() -> None:
    shape = tentacle_shape(0.2, 0.1, 0.02, 10, 0.1)
    assert_allclose(shape.scales, [1.0, 0.9, 0.8, 0.7, 0.6, 0.5, 0.4, 0.3, 0.2, 0.1], atol=1e-15)
    assert_allclose(shape.lengths, 0.1 * shape.scales, atol=1e-15)
    assert_allclose(shape.radii, 0.02 * shape.scales, atol=1e-15)
    # c1 = 0.25 + (0.1 + 0.09) / 2; c9 = 0.25 + (0.1 + 2 * (0.09 + ... + 0.02) + 0.01) / 2
    assert_allclose(shape.centres[[0, 1, 9]], [0.25, 0.345, 0.745], atol=1e-15)


def test_end_scale_one_gives_uniform_links() -> None:
    assert_allclose(link_scales(5, 1.0), np.ones(5))


@pytest.mark.parametrize(
    ("count", "expected"),
    [
        (3, [[1, 0, 0], [-0.5, H, 0], [-0.5, -H, 0]]),
        (6, [[1, 0, 0], [0.5, H, 0], [-0.5, H, 0], [-1, 0, 0], [-0.5, -H, 0], [0.5, -H, 0]]),
        (
            8,
            [
                [1, 0, 0],
                [S, S, 0],
                [0, 1, 0],
                [-S, S, 0],
                [-1, 0, 0],
                [-S, -S, 0],
                [0, -1, 0],
                [S, -S, 0],
            ],
        ),
    ],
)
def test_tentacle_axes_counter_clockwise_about_z(count: int, expected: list[list[float]]) -> None:
    scene = with_defaults({"version": 1, "creatures": [{"tentacles": {"count": count}}]})
    layout = creature_layout(scene["creatures"][0])  # heading 0: creature frame = world
    assert_allclose([layout.axis(k) for k in range(count)], expected, atol=1e-15)
    assert_allclose(tentacle_angles(count), np.radians(360.0 * np.arange(count) / count))


@pytest.mark.parametrize(("links", "end_scale"), [(0, 0.5), (3, 0.0), (3, 1.5)])
def test_impossible_tentacles_are_refused(links: int, end_scale: float) -> None:
    with pytest.raises(ValueError):
        link_scales(links, end_scale)


def test_rest_pitch_lays_the_underside_on_the_ground() -> None:
    shape = tentacle_shape(0.2, 0.1, 0.02, 2, 0.5)  # drop 0.01 over 0.15
    assert shape.length == pytest.approx(0.15)
    assert shape.rest_pitch == pytest.approx(np.arcsin(0.01 / 0.15))
    assert tentacle_shape(0.2, 0.1, 0.02, 1, 0.5).rest_pitch == 0.0


@pytest.mark.parametrize(
    ("link_length", "link_radius"), [(0.01, 0.025), (0.07, 10.0)], ids=["short", "fat"]
)
def test_rest_pitch_of_a_stub_whose_tip_cannot_reach_the_ground_is_straight_down(
    link_length: float, link_radius: float
) -> None:
    shape = tentacle_shape(0.15, link_length, link_radius, 2, 0.3)
    assert (shape.radii[0] - shape.radii[-1]) > shape.length  # arcsin of > 1 before
    assert shape.rest_pitch == np.pi / 2


def test_the_layout_is_where_the_build_puts_every_body(make_world: Callable[..., World]) -> None:
    spec = {
        "name": "octo",
        "position": [1.0, -2.0],
        "heading_deg": 30,
        "tentacles": {"count": 5, "links": 4, "overrides": [{"index": 3, "link_radius": 0.04}]},
    }
    world = make_world({"version": 1, "creatures": [spec]})
    layout = creature_layout(world.scene["creatures"][0])  # type: ignore[index]
    assert_allclose(layout.origin, [1.0, -2.0, 0.04])  # the thickest first link rests
    creature = world.component(world.creature("octo"), Creature)
    starts, ends, radii = layout.capsules()
    row = 1
    for k, entity in enumerate(creature.tentacles):
        links = world.component(entity, Tentacle).links
        built = np.array([world.component(e, Transform).pos for e in links])
        assert_allclose(layout.link_centres(k), built, atol=1e-12)
        assert_allclose(0.5 * (starts + ends)[row : row + len(links)], built, atol=1e-12)
        assert_allclose(
            radii[row : row + len(links)], [world.component(e, Link).radius for e in links]
        )
        row += len(links)
    mantle = world.component(world.creature("octo"), Transform).pos
    assert_allclose(0.5 * (starts[0] + ends[0]), mantle, atol=1e-12)


def _compiled_body(geom: dict[str, object]) -> tuple[float, float]:
    """(mass, smallest principal inertia) MuJoCo compiles for a free body of one geom."""
    spec = mujoco.MjSpec()
    body = spec.worldbody.add_body()
    body.add_freejoint()
    body.add_geom(**geom)
    model = spec.compile()
    return float(model.body_mass[1]), float(model.body_inertia[1].min())


@pytest.mark.parametrize(("length", "radius", "density"), [(0.07, 0.025, 1000), (0.01, 0.03, 20)])
def test_capsule_mass_and_inertia_are_mujocos(length: float, radius: float, density: float) -> None:
    capsule = mujoco.mjtGeom.mjGEOM_CAPSULE
    fromto = [-0.5 * length, 0, 0, 0.5 * length, 0, 0]
    geom = {"type": capsule, "fromto": fromto, "size": [radius, 0, 0], "density": density}
    expected = capsule_mass_inertia(np.array([length]), np.array([radius]), density)[0]
    assert_allclose(_compiled_body(geom), expected, rtol=1e-9)


@pytest.mark.parametrize(("radius", "height"), [(0.15, 0.2), (0.2, 0.01), (0.05, 1.0)])
def test_cylinder_mass_and_inertia_are_mujocos(radius: float, height: float) -> None:
    cylinder = mujoco.mjtGeom.mjGEOM_CYLINDER
    geom = {"type": cylinder, "size": [radius, 0.5 * height, 0], "density": 400.0}
    assert_allclose(_compiled_body(geom), cylinder_mass_inertia(radius, height, 400.0), rtol=1e-9)


def test_a_creatures_reach_is_its_mantle_and_longest_tentacle_and_thickest_link() -> None:
    # two links at scales 1 and 0.5: 0.3 + 0.15 m long; the first is the thickest (5 cm)
    tentacles = {"count": 4, "links": 2, "link_length": 0.3, "link_radius": 0.05}
    creature = {"mantle": {"radius": 0.4}, "tentacles": {**tentacles, "end_scale": 0.5}}
    assert creature_reach(creature) == pytest.approx(0.4 + 0.45 + 0.05)
    # one tentacle made longer by its override reaches further
    creature["tentacles"]["overrides"] = [{"index": 2, "link_length": 0.5}]
    assert creature_reach(creature) == pytest.approx(0.4 + 0.75 + 0.05)
