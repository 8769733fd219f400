"""Creatures' physics views: one compiled model per morphology, threads, a creature alone."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
from numpy.testing import assert_array_equal

from ecs_tentacles.components import Creature
from ecs_tentacles.world import World


def _far_apart(tentacles: list[dict[str, Any]], goals: bool = True) -> dict[str, Any]:
    """Creatures 4 m apart in a row, each with its own tentacle settings and a goal."""
    creatures = [
        {
            "name": f"c{i}",
            "position": [4.0 * i, 0.0],
            "tentacles": spec,
            "goals": [{"position": [4.0 * i, 1.0]}] if goals else [],
        }
        for i, spec in enumerate(tentacles)
    ]
    return {"version": 1, "creatures": creatures}


def test_one_compile_per_morphology(make_world: Callable[..., World]) -> None:
    same = {"count": 4, "links": 5}
    world = make_world(_far_apart([same, same, {"count": 5, "links": 5}, same]))
    physics = world.physics
    assert (len(physics.views), physics.compiles) == (4, 2)
    assert [g.creatures for g in physics.views] == [[world.creature(f"c{i}")] for i in range(4)]
    # creatures of one morphology share its model; each owns its state and servo gains
    first, second, third = physics.views[0], physics.views[1], physics.views[2]
    assert first.model is second.model is not third.model
    assert first.batch is second.batch is not third.batch and first.row != second.row
    assert not np.shares_memory(first.kp, second.kp)
    assert not np.shares_memory(first.data.qpos, second.data.qpos)


def test_trajectories_do_not_depend_on_the_thread_count(make_world: Callable[..., World]) -> None:
    scene = _far_apart([{"count": 4, "links": 5}] * 3 + [{"count": 3, "links": 6}])
    runs = []
    for threads in (1, 2):
        world = make_world(scene, threads=threads)
        assert world.physics.threads == threads
        poses = []
        for _ in range(6):
            world.step(10)
            poses.append(world.transforms.pos.copy())
        runs.append(np.array(poses))
    assert_array_equal(runs[0], runs[1])
    assert np.ptp(runs[0][:, :, :2], axis=0).max() > 0.01  # they did move


def test_a_creature_alone_moves_as_in_a_world_of_its_own(make_world: Callable[..., World]) -> None:
    # the first creature draws the same random tentacle phases in both worlds
    crowd = make_world(_far_apart([{"count": 4, "links": 5}, {"count": 6}, {"count": 3}]))
    alone = make_world(_far_apart([{"count": 4, "links": 5}]))
    rows = crowd.physics.views[0].body_rows
    assert_array_equal(rows, alone.physics.views[0].body_rows)
    for _ in range(5):
        crowd.step(24)
        alone.step(24)
        assert_array_equal(crowd.transforms.pos[rows], alone.transforms.pos)
        assert_array_equal(crowd.transforms.quat[rows], alone.transforms.quat)


def test_groups_are_visible(make_world: Callable[..., World]) -> None:
    world = make_world(_far_apart([{"count": 3, "links": 4}] * 2), threads=2)
    octo = world.component(world.creature("c1"), Creature)
    assert world.physics.view_of(octo) is world.physics.views[1]
    assert repr(world.physics) == "<physics: 2 creatures, 1 compiled models, 2 threads>"
    assert world.physics.bodies == 2 * (1 + 3 * 4)


def test_sync_copies_consecutive_rows_as_one_slice_and_follows_a_despawn() -> None:
    """A uniform crowd's bodies are consecutive store rows: one copy instead of a scatter
    (the pose of every body must land exactly where the scatter put it)."""
    from ecs_tentacles.creator.crowd import crowd_scene

    with World.from_scene(crowd_scene(6, seed=0, uniform=True)) as world:
        world.step(3)
        (batch,) = world.physics.batches
        assert batch.body_span() == slice(0, batch.body_rows.size)
        world.despawn(world.creature(world.creature_name(int(world.creatures.entity[2]))))
        world.step(2)
        for scattered in (False, True):  # consecutive after the despawn; then not
            if scattered:
                batch.body_rows = batch.body_rows[::-1].copy()  # rows in another order
                assert batch.body_span() is None
            world.transforms.pos[:] = np.nan
            world.transforms.quat[:] = np.nan
            batch.sync(world.transforms)
            np.testing.assert_array_equal(world.transforms.pos[batch.body_rows], batch.xpos)
            np.testing.assert_array_equal(world.transforms.quat[batch.body_rows], batch.xquat)
            assert np.isfinite(world.transforms.pos[batch.body_rows]).all()


def test_the_old_names_still_work_and_say_so(make_world: Callable[..., World]) -> None:
    world = make_world(_far_apart([{"count": 4, "links": 5}]))
    creature = world.component(world.creature("c0"), Creature)
    with pytest.warns(DeprecationWarning, match="physics.view_of"):
        assert world.physics.group_of(creature) is world.physics.view_of(creature)
    with pytest.warns(DeprecationWarning, match="physics.views"):
        assert world.physics.groups is world.physics.views
