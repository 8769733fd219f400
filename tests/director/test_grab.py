"""The grab spring: bounded by the creature's mass, aimed on the plane facing the camera."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from ecs_tentacles.director.grab import MAX_ACCELERATION, Grab, spring_force

vectors = st.lists(st.floats(-1e3, 1e3), min_size=3, max_size=3).map(np.array)


@settings(max_examples=200, deadline=None)
@given(vectors, vectors, vectors, st.floats(0.01, 500.0))
def test_the_force_never_exceeds_the_creature_mass_times_the_limit(pos, vel, target, mass):
    force = spring_force(pos, vel, target, mass)
    assert np.linalg.norm(force) <= mass * MAX_ACCELERATION * (1 + 1e-9)


def test_the_spring_pulls_toward_the_target_and_damps_the_speed():
    pulled = spring_force(np.zeros(3), np.zeros(3), np.array([0.01, 0.0, 0.0]), 2.0)
    assert pulled[0] > 0 and np.allclose(pulled[1:], 0.0)
    damped = spring_force(np.zeros(3), np.array([0.0, 0.1, 0.0]), np.zeros(3), 2.0)
    assert damped[1] < 0


def test_the_mouse_ray_meets_the_plane_through_the_grab_point():
    point = np.array([1.0, 2.0, 0.3])
    grab = Grab(7, 0, point.copy(), point.copy(), np.array([0.0, -1.0, 0.0]))
    grab.aim(np.array([0.0, -5.0, 1.0]), np.array([0.0, 1.0, 0.0]))
    assert np.allclose(grab.target, [0.0, 2.0, 1.0])
    grab.aim(np.array([0.0, -5.0, 1.0]), np.array([1.0, 0.0, 0.0]))  # parallel: unchanged
    assert np.allclose(grab.target, [0.0, 2.0, 1.0])


def test_the_grab_system_touches_only_what_it_declares_and_lets_go() -> None:
    from ecs_tentacles.components import Transform
    from ecs_tentacles.director.plugin import DirectorPlugin
    from ecs_tentacles.director.state import Director
    from ecs_tentacles.world import World
    from tests.declarations import step_declared

    with World.from_scene("octopus") as world:
        world.add_plugin(DirectorPlugin())
        octo = world.creature("octopus")
        start = world.component(octo, Transform).pos.copy()
        up = start + [0.0, 0.0, 0.6]
        world.resource(Director).grab = Grab(octo, 0, up, start.copy(), np.array([0, -1.0, 0]))
        step_declared(world, 40)  # the spring's system with only its declared columns
        assert world.component(octo, Transform).pos[2] > start[2] + 0.2
        world.resource(Director).grab = None
        world.step(1)
        assert not world.physics.views[0].batch.applied  # the force is gone
        world.step(120)
        assert world.physics.health.recoveries == 0
