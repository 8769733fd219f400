"""Scatter: seeded, never overlapping, clear of obstacles, fast enough for a brush."""

from __future__ import annotations

import numpy as np
import pytest

from ecs_tentacles.components import Creature, Transform
from ecs_tentacles.creatures.spawning import SpawnError, creature_entry
from ecs_tentacles.director.scatter import GAP, reach_of, scatter, spots
from ecs_tentacles.world import World

OCTO = {"name": "octo", "tentacles": {"count": 6, "links": 5}}


def _scene() -> dict:
    return {"version": 1, "creatures": [{"name": "here", "position": [0.0, 0.0]}]}


def _placed(world: World, entities: list[int]) -> np.ndarray:
    rows = [world.component(e, Transform) for e in entities]
    return np.array([[*t.pos[:2]] for t in rows])


def test_a_seed_gives_the_same_spots_and_headings_every_time():
    with World.from_scene(_scene()) as one, World.from_scene(_scene()) as two:
        a = scatter(one, OCTO, (1.0, 2.0), 4.0, 12, seed=5)
        b = scatter(two, OCTO, (1.0, 2.0), 4.0, 12, seed=5)
        first = _placed(one, a)
        assert np.array_equal(first, _placed(two, b))
        headings = [one.creature_specs[e]["heading_deg"] for e in a]
        assert headings == [two.creature_specs[e]["heading_deg"] for e in b]
        assert len(set(np.round(headings, 3))) == len(a)  # random headings
    with World.from_scene(_scene()) as three:
        c = scatter(three, OCTO, (1.0, 2.0), 4.0, 12, seed=6)
        assert not np.array_equal(_placed(three, c)[:3], first[:3])


def test_scattered_creatures_never_overlap_each_other_or_those_there():
    with World.from_scene(_scene()) as world:
        made = scatter(world, OCTO, (0.0, 0.0), 5.0, 30, seed=1)
        assert 5 <= len(made) <= 30
        reach = reach_of(creature_entry(world, OCTO))
        points = _placed(world, made)
        gap = np.linalg.norm(points[:, None] - points[None], axis=2)
        np.fill_diagonal(gap, np.inf)
        assert gap.min() >= 2 * reach + GAP - 1e-9
        names = {c.name for _, c in world.query(Creature)}
        assert len(names) == len(made) + 1  # every one named apart
        world.step(30)
        assert world.physics.health.recoveries == 0


def test_a_full_disc_gives_fewer_and_obstacles_are_kept_clear():
    rock = {"obstacles": [{"shape": "box", "position": [0.0, 0.0, 0.5], "size": [4, 4, 1]}]}
    scene = {"version": 1, "terrain": rock, "creatures": [{"name": "far", "position": [20, 0]}]}
    with World.from_scene(scene) as world:
        found = spots(world, creature_entry(world, OCTO), (0.0, 0.0), 5.0, 50, seed=2)
        reach = reach_of(creature_entry(world, OCTO))
        assert len(found) < 50
        assert (np.abs(found[:, :2]).max(axis=1) > 2.0 + 0.5 * reach).all()


def test_a_bad_entry_is_one_line_naming_the_field():
    with World.from_scene(_scene()) as world:
        with pytest.raises(SpawnError, match=r"^creature\.tentacles\.links: "):
            scatter(world, {"tentacles": {"links": 0}}, (0, 0), 3.0, 5)
        with pytest.raises(ValueError, match="count must be >= 0"):
            spots(world, creature_entry(world, OCTO), (0, 0), 3.0, -1, 0)


def test_scatter_keeps_every_creature_on_the_heightfield():
    """On rocky_shore (a 14 x 10 m heightfield) a brush over its edge placed creatures at
    x = -7.16 and 7.26: they dropped off it."""
    with World.from_scene("rocky_shore") as world:
        entry = creature_entry(world, {"name": "s", "tentacles": {"count": 5, "links": 4}})
        reach = reach_of(entry)
        found = np.concatenate(
            [spots(world, entry, centre, 3.0, 12, seed) for seed in range(4)
             for centre in ((-7.0, 0.0), (7.0, 4.5), (0.0, -5.0))]
        )  # fmt: skip
        assert len(found) >= 12  # the inner half of each disc still takes creatures
        assert (np.abs(found[:, 0]) + reach <= 7.0).all()
        assert (np.abs(found[:, 1]) + reach <= 5.0).all()
        made = scatter(world, entry, (-7.0, 0.0), 3.0, 6, seed=1)
        world.step(30)
        for entity in made:
            x, y = world.component(entity, Transform).pos[:2]
            assert abs(x) < 7.0 and abs(y) < 5.0
