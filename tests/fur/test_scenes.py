"""The bundled fur scenes load, run and show what they say."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ecs_tentacles.fur import Fur, guide_curves
from ecs_tentacles.fur.stores import FurData
from ecs_tentacles.numeric.quaternions import quat_rotate
from ecs_tentacles.world import World


def mean_elevation(world: World) -> float:
    g = world.resource(FurData).guides
    normals = quat_rotate(world.transforms.quat[g.body_row], g.normal)
    return float(np.mean(np.sum(world.resource(FurData).frames[:, 0] * normals, axis=1)))


def test_hedgehog_octopus_bristles_when_the_roach_comes_near(
    make_world: Callable[..., World],
) -> None:
    world = make_world("hedgehog_octopus")
    fur = world.component(world.creature("hedgehog"), Fur)
    assert fur.preset == "hedgehog" and len(fur.guides) == 500
    world.step(60)
    calm = mean_elevation(world)
    assert world.resource(FurData).emotions.level[0] == 0.0 and calm < 0.2
    world.step(4 * 60)  # the roach arrives at 3 s
    assert world.resource(FurData).emotions.level[0] > 0.9
    assert mean_elevation(world) > calm + 0.4
    assert np.isfinite(guide_curves(world).points).all()


def test_fur_presets_has_one_creature_per_preset(make_world: Callable[..., World]) -> None:
    world = make_world("fur_presets")
    world.step(2)
    presets = {world.component(e, Fur).preset for e, _ in world.query(Fur)}
    assert presets == {"hedgehog", "cat", "bird"}
    assert (
        world.resource(FurData).points == 8
    )  # the most any fur asks for (the cat): all guides share it
    assert (
        np.isfinite(world.resource(FurData).curves).all()
        and len(world.resource(FurData).curves) == 400 + 600 + 160
    )
