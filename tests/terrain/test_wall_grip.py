"""Suckers hold a creature's weight on a vertical wall: anchored by the suckers that touch
the wall (within the suckers system's attach distance of it), a creature pressed flat
against a wall, high above the ground, stays within 5 cm for 5 s; without them it falls."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from ecs_tentacles.ground import ground_of
from ecs_tentacles.locomotion.grip import attach, sucker_points
from ecs_tentacles.locomotion.systems.suckers import ATTACH_HEIGHT
from ecs_tentacles.world import World

WALL = {"shape": "box", "position": [-0.25, 0, 1.0], "size": [0.5, 4.0, 4.0]}  # face at x = 0
SCENE = {
    "version": 1,
    "terrain": {"obstacles": [WALL]},
    "plugins": {"locomotion": False, "suckers": False},  # nothing but the grip holds it
    "creatures": [
        {"name": "climber", "position": [3.0, 0, 1.5], "tentacles": {"suckers": "every_link"}}
    ],
}


def _against_the_wall(world: World) -> None:
    """The creature flat on the wall, its underside 2 mm from it, 1.5 m up."""
    physics = world.physics
    batch = physics.batches[0]
    qpos, qvel = np.zeros(batch.model.nq), np.zeros(batch.model.nv)
    root = batch.root_qpos
    underside = 0.1 + 0.025  # half the mantle's height + the thickest link's radius
    qpos[root : root + 3] = [underside + 0.002, 0.0, 1.5]
    qpos[root + 3 : root + 7] = [np.cos(np.pi / 4), 0.0, np.sin(np.pi / 4), 0.0]  # up -> +x
    physics.place_joints(0, qpos, qvel)
    physics.sync(world.transforms)


@pytest.mark.parametrize("grip", [True, False], ids=["gripping", "not gripping"])
def test_suckers_on_a_vertical_wall_hold_the_creature(
    make_world: Callable[..., World], grip: bool
) -> None:
    world = make_world(SCENE)
    _against_the_wall(world)
    touching = np.flatnonzero(ground_of(world).distance(sucker_points(world)) <= ATTACH_HEIGHT)
    assert len(touching) >= 8  # the thick inner links of every tentacle
    if grip:
        for row in touching.tolist():
            attach(world, int(world.suckers.entity[row]))
    mantle = world.creatures.mantle_row[0]
    start = world.transforms.pos[mantle].copy()
    moved = 0.0
    for _ in range(300):  # 5 s
        world.step()
        moved = max(moved, float(np.linalg.norm(world.transforms.pos[mantle] - start)))
    if grip:
        assert moved <= 0.05 and world.suckers.attached.sum() == len(touching)
    else:
        assert moved > 0.5  # it falls
    assert world.physics.health.recoveries == 0
