"""crowd_scene: deterministic, valid, varied, no overlap at build, paths that cross."""

from __future__ import annotations

import json
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

from ecs_tentacles.components import Creature, Link, Tentacle, Transform
from ecs_tentacles.creator.crowd import CLEARANCE, crowd_scene
from ecs_tentacles.scene.construction import creature_reach
from ecs_tentacles.scene.load import load_scene
from ecs_tentacles.world import World


def positions(scene: dict[str, Any]) -> np.ndarray:
    return np.array([c["position"] for c in scene["creatures"]], dtype=float)


def test_same_seed_same_json_other_seed_other_json() -> None:
    first = json.dumps(crowd_scene(17, seed=5))
    assert json.dumps(crowd_scene(17, seed=5)) == first
    assert json.dumps(crowd_scene(17, seed=6)) != first


@pytest.mark.parametrize("n", [1, 2, 17])
def test_small_crowds_validate_build_and_run_stably(
    n: int, make_world: Callable[..., World]
) -> None:
    scene = crowd_scene(n, seed=n)
    assert len(load_scene(scene)["creatures"]) == n
    world = make_world(scene)
    assert sum(len(group.creatures) for group in world.physics.views) == n
    world.step(20)
    assert world.events.counts["creature_recovered"] == 0  # the physics never failed
    assert np.isfinite(world.transforms.pos).all()
    assert {c.name for _, c in world.query(Creature)} == {c["name"] for c in scene["creatures"]}


def test_a_large_crowd_validates() -> None:
    scene = load_scene(crowd_scene(256, seed=2))
    assert len(scene["creatures"]) == 256


def test_creatures_vary() -> None:
    creatures = load_scene(crowd_scene(256, seed=3))["creatures"]
    counts = {c["tentacles"]["count"] for c in creatures}
    assert counts == set(range(3, 9))
    furry = [c for c in creatures if "fur" in c]
    assert 0.1 * 256 < len(furry) < 0.5 * 256
    assert {c["fur"]["preset"] for c in furry} == {"hedgehog", "cat", "bird"}
    assert max(c["fur"]["groom"]["count"] for c in furry) <= 48
    assert all(c["tentacles"]["overrides"] for c in creatures)  # every plan has its own tentacle
    radii = {c["mantle"]["radius"] for c in creatures}
    links = {o["links"] for c in creatures for o in c["tentacles"]["overrides"] if "links" in o}
    assert len(radii) == 8 and len(links) >= 3  # 8 body plans by default
    assert {c["locomotion"]["gait"] for c in creatures} == {"cyclic", "coordinated"}
    assert len({c["heading_deg"] for c in creatures}) == 256


def test_uniform_crowds_are_one_morphology_with_varied_behaviour() -> None:
    creatures = load_scene(crowd_scene(40, seed=2, uniform=True))["creatures"]
    default = load_scene({"version": 1, "creatures": [{}]})["creatures"][0]
    shape = ("count", "links", "link_length", "link_radius", "end_scale")
    for creature in creatures:
        assert creature["mantle"] == default["mantle"]
        assert {k: creature["tentacles"][k] for k in shape} == {
            k: default["tentacles"][k] for k in shape
        }
        assert all(
            set(o) <= {"index", "speed", "wave_frequency"}
            for o in creature["tentacles"]["overrides"]
        )
    assert len({c["tentacles"]["wave_frequency"] for c in creatures}) == 40
    assert any("fur" in c for c in creatures)


@pytest.mark.parametrize(("n", "spacing"), [(17, None), (256, None), (30, 4.0)])
def test_reach_circles_never_overlap(n: int, spacing: float | None) -> None:
    scene = crowd_scene(n, seed=n, spacing=spacing)
    where = positions(scene)
    reach = np.array([creature_reach(c) for c in load_scene(scene)["creatures"]])
    apart = np.linalg.norm(where[:, None] - where[None], axis=-1)
    allowed = reach[:, None] + reach[None]
    off_diagonal = ~np.eye(n, dtype=bool)
    assert (apart[off_diagonal] >= allowed[off_diagonal]).all()
    if spacing is None:  # the default spacing keeps half the clearance after jitter
        assert apart[off_diagonal].min() >= 2 * reach.max() + 0.5 * CLEARANCE - 1e-3


def test_reach_holds_every_built_link(make_world: Callable[..., World]) -> None:
    scene = crowd_scene(8, seed=11)
    reach = {c["name"]: creature_reach(c) for c in load_scene(scene)["creatures"]}
    world = make_world(scene)
    for entity, creature in world.query(Creature):
        centre = world.component(entity, Transform).pos[:2]
        farthest = 0.0
        for tentacle in creature.tentacles:
            for link_entity in world.component(tentacle, Tentacle).links:
                link = world.component(link_entity, Link)
                middle = np.linalg.norm(world.component(link_entity, Transform).pos[:2] - centre)
                farthest = max(farthest, middle + 0.5 * link.length + link.radius)
        assert farthest <= reach[creature.name] + 1e-9
        assert farthest >= reach[creature.name] - 0.05  # and the reach is not loose


def test_goals_cross_the_centre_and_idle_creatures_have_none() -> None:
    scene = crowd_scene(64, seed=1)
    where = positions(scene)
    goals = np.array([c["goals"][0]["position"] for c in scene["creatures"]])
    np.testing.assert_allclose(where.mean(axis=0), 0.0, atol=0.1)
    spacing = 2 * max(creature_reach(c) for c in scene["creatures"]) + CLEARANCE
    assert (np.linalg.norm(goals - where, axis=1) >= 0.9 * spacing).all()
    assert (np.einsum("ij,ij->i", goals, where) < 0).all()  # every goal is across the centre
    idle = crowd_scene(20, seed=1, idle=0.25)["creatures"]
    assert sum("goals" not in c for c in idle) == 5
    assert all("goals" not in c for c in crowd_scene(3, idle=1.0)["creatures"])


def test_one_creature_gets_a_goal_away_from_itself() -> None:
    (creature,) = crowd_scene(1)["creatures"]
    distance = np.linalg.norm(np.subtract(creature["goals"][0]["position"], creature["position"]))
    assert distance >= 2 * creature_reach(creature)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"n": 0}, "N: must be >= 1, got 0"),
        ({"n": 16385}, "N: must be <= 16384, the most a scene holds, got 16385"),
        ({"n": 4, "idle": 1.5}, "idle: must be in [0, 1], got 1.5"),
        ({"n": 4, "species": 0}, "species: must be >= 1, got 0"),
        ({"n": 4, "spacing": 0.5}, "spacing: must be >= "),
    ],
)
def test_bad_arguments_name_themselves(kwargs: dict[str, Any], message: str) -> None:
    with pytest.raises(ValueError, match="^" + message.replace("[", r"\[").replace("]", r"\]")):
        crowd_scene(**kwargs)
