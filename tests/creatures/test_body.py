"""Scene -> entities -> MuJoCo bodies: poses follow the construction rules exactly."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.testing import assert_allclose

from ecs_tentacles.components import Creature, Link, Motor, Sucker, Tentacle, Transform
from ecs_tentacles.scene.construction import tentacle_shape
from ecs_tentacles.world import World

SCENE = {
    "version": 1,
    "creatures": [
        {
            "name": "octo",
            "position": [1.0, 2.0, 0.05],
            "mantle": {"radius": 0.2, "height": 0.3},
            "tentacles": {
                "count": 8,
                "links": 10,
                "link_length": 0.1,
                "link_radius": 0.02,
                "end_scale": 0.1,
                "strength": 5.0,
                "overrides": [
                    {"index": 2, "links": 3, "link_length": 0.2, "end_scale": 0.5, "strength": 9.0}
                ],
            },
        }
    ],
}


def _tentacle(world: World, k: int) -> Tentacle:
    creature = world.component(world.creature("octo"), Creature)
    return world.component(creature.tentacles[k], Tentacle)


def test_link_centres_lie_on_the_rotated_axes(make_world: Callable[..., World]) -> None:
    world = make_world(SCENE)
    origin = np.array([1.0, 2.0, 0.05])
    for k in (0, 1, 5):
        tentacle = _tentacle(world, k)
        angle = np.radians(45.0 * k)
        axis = np.array([np.cos(angle), np.sin(angle), 0.0])
        shape = tentacle_shape(0.2, 0.1, 0.02, 10, 0.1)
        positions = np.array([world.component(e, Transform).pos for e in tentacle.links])
        assert_allclose(positions, origin + shape.centres[:, None] * axis, atol=1e-12)
        links = [world.component(e, Link) for e in tentacle.links]
        assert_allclose([link.radius for link in links], shape.radii, atol=1e-15)
        assert_allclose([link.length for link in links], shape.lengths, atol=1e-15)
    mantle = world.component(world.creature("octo"), Transform)
    assert_allclose(mantle.pos, [1.0, 2.0, 0.05 + 0.15], atol=1e-12)


def test_override_changes_one_tentacle_only(make_world: Callable[..., World]) -> None:
    world = make_world(SCENE)
    odd = _tentacle(world, 2)  # along +y
    assert len(odd.links) == 3
    positions = np.array([world.component(e, Transform).pos for e in odd.links])
    # lengths 0.2, 0.15, 0.1 -> centres 0.3, 0.475, 0.6 from the mantle axis
    assert_allclose(positions, [[1.0, 2.3, 0.05], [1.0, 2.475, 0.05], [1.0, 2.6, 0.05]], atol=1e-12)
    assert_allclose([world.component(e, Link).radius for e in odd.links], [0.02, 0.015, 0.01])
    assert_allclose([world.component(e, Motor).strength for e in odd.links], [9.0, 6.75, 4.5])
    assert [len(_tentacle(world, k).links) for k in range(8)] == [10, 10, 3, 10, 10, 10, 10, 10]
    assert world.component(_tentacle(world, 3).links[0], Motor).strength == 5.0


def test_every_link_has_a_motor_and_every_tip_a_sucker(make_world: Callable[..., World]) -> None:
    world = make_world(SCENE)
    links = {e for e, _ in world.query(Link)}
    assert links == {e for e, _ in world.query(Link, Motor)}
    assert len(links) == 7 * 10 + 3
    tips = {world.component(e, Tentacle).links[-1] for e, _ in world.query(Tentacle)}
    assert {s.link for _, s in world.query(Sucker)} == tips
    model = world.physics.views[0].model
    assert (len(world.physics.views[0].body_ids), model.nu, model.neq) == (1 + 73, 2 * 73, 8)


def test_suckers_along_the_tentacle(make_world: Callable[..., World]) -> None:
    scene = {
        "version": 1,
        "creatures": [{"tentacles": {"count": 3, "links": 4, "suckers": "every_link"}}],
    }
    world = make_world(scene)
    assert len(world.suckers) == 12
    assert world.physics.views[0].model.neq == 12
    assert not world.suckers.attached.any()


def test_twist_adds_a_third_hinge(make_world: Callable[..., World]) -> None:
    world = make_world(
        {"version": 1, "creatures": [{"tentacles": {"count": 3, "links": 2, "twist": True}}]}
    )
    assert world.physics.views[0].model.nu == 3 * 2 * 3


def test_heading_rotates_the_whole_creature(make_world: Callable[..., World]) -> None:
    scene = {
        "version": 1,
        "creatures": [{"name": "octo", "heading_deg": 90, "tentacles": {"count": 4}}],
    }
    world = make_world(scene)
    base = world.component(_tentacle(world, 0).links[0], Transform).pos
    assert_allclose(base[:2], [0.0, 0.15 + 0.035], atol=1e-12)  # tentacle 0 now along +y


def test_a_creatures_random_draws_do_not_depend_on_the_other_creatures() -> None:
    creature = {"name": "b", "position": [3, 0], "tentacles": {"count": 5, "links": 3}}
    other = {"name": "a", "position": [0, 0], "tentacles": {"count": 7, "links": 3}}
    phases = []
    for creatures in ([creature], [other, creature]):
        scene = {"version": 1, "seed": 11, "creatures": creatures}
        with World.from_scene(scene) as world:
            row = world.component(world.creature("b"), Creature).row
            first = world.creatures.first_tentacle[row]
            phases.append(world.stores["locomotion.tentacles"].phase[first : first + 5].copy())
    np.testing.assert_array_equal(phases[0], phases[1])
    assert len(set(phases[0].tolist())) == 5
    with World.from_scene({"version": 1, "seed": 12, "creatures": [creature]}) as world:
        assert not np.array_equal(
            world.stores["locomotion.tentacles"].phase[:5], phases[0]
        )  # the seed matters


def test_tentacles_of_one_shape_share_their_links_numbers(make_world: Callable[..., World]) -> None:
    world = make_world(
        {
            "version": 1,
            "creatures": [
                {"name": f"c{i}", "position": [3.0 * i, 0.0], "tentacles": {"count": 3}}
                for i in range(2)
            ],
        }
    )
    firsts = [
        world.component(world.component(t, Tentacle).links[0], Link)
        for _, creature in world.query(Creature)
        for t in creature.tentacles
    ]
    assert len(firsts) == 6 and len({id(link) for link in firsts}) == 6  # a Link each
    assert len({id(link.length) for link in firsts}) == 1  # one float for them all
    assert len({(link.length, link.radius, link.scale) for link in firsts}) == 1
