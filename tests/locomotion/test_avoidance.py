"""Crowd avoidance: the social-force term, its switches, and a crossing crowd that touches less."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

from ecs_tentacles.creator.crowd import crowd_scene
from ecs_tentacles.locomotion.avoidance import KERNELS, Avoidance, bend, bent
from ecs_tentacles.locomotion.stores import LocomotionStores
from ecs_tentacles.scene.errors import SceneError
from ecs_tentacles.scene.load import load_scene
from ecs_tentacles.world import World
from tests.conftest import ByBackend


def _pair(apart: float, **creature: Any) -> dict[str, Any]:
    """Two octopuses `apart` m apart on x, each with a goal past the other (head-on)."""
    half = apart / 2
    return {
        "version": 1,
        "creatures": [
            {"name": "west", "position": [-half, 0.0], "goals": [{"position": [half + 2, 0.0]}],
             **creature},
            {"name": "east", "position": [half, 0.0], "goals": [{"position": [-half - 2, 0.0]}]},
        ],
    }  # fmt: skip


def test_head_on_neighbours_step_aside_to_their_right() -> None:
    pos = np.array([[0.0, 0.0], [1.5, 0.0], [9.0, 9.0]])
    radius = np.full(3, 0.5)
    heading = np.array([[1.0, 0.0], [-1.0, 0.0], [0.0, 0.0]])
    steering = np.array([True, True, False])
    term = bend(pos, radius, heading, steering, np.full(3, 5.0), reach=1.0, strength=1.0)
    # gap 0.5 of a 1 m range: push (1 - 0.5)^2, the neighbour dead ahead weighs fully
    np.testing.assert_allclose(term[0], [-0.25, -0.25], rtol=0, atol=1e-12)
    np.testing.assert_allclose(term[1], [0.25, 0.25], rtol=0, atol=1e-12)
    assert np.all(term[2] == 0.0)  # nobody near, and it does not steer


def test_beyond_range_the_term_is_exactly_zero_and_the_direction_unchanged() -> None:
    pos = np.array([[0.0, 0.0], [2.1, 0.0]])
    radius = np.full(2, 0.5)
    heading = np.array([[1.0, 0.0], [-1.0, 0.0]])
    term = bend(pos, radius, heading, np.ones(2, bool), np.full(2, 5.0), reach=1.0, strength=2.0)
    assert np.all(term == 0.0)
    to_goal = np.array([[3.0, 0.1], [-3.0, 0.2]])
    assert bent(to_goal, term) is to_goal
    one = term.copy()
    one[1] = [0.5, 0.0]
    turned = bent(to_goal, one)
    assert np.array_equal(turned[0], to_goal[0])  # untouched row: bit for bit
    np.testing.assert_allclose(turned[1], to_goal[1] + np.hypot(-3.0, 0.2) * np.array([0.5, 0]))


def test_the_term_fades_out_at_the_goal() -> None:
    pos = np.array([[0.0, 0.0], [1.5, 0.0]])
    heading = np.array([[1.0, 0.0], [0.0, 0.0]])
    args = (pos, np.full(2, 0.5), heading, np.array([True, False]))
    near = bend(*args, np.array([0.1, 0.0]), reach=1.0, strength=1.0)
    far = bend(*args, np.array([5.0, 0.0]), reach=1.0, strength=1.0)
    np.testing.assert_allclose(near[0], 0.2 * far[0])  # 0.1 m of a 0.5 m personal radius


def _terms(world: World, frames: int = 3) -> np.ndarray:
    world.step(frames)
    return world.resource(LocomotionStores).creatures.avoidance.copy()


def test_avoid_false_per_creature_and_the_scene_switch(make_world: Callable[..., World]) -> None:
    on = _terms(make_world(_pair(1.6)))
    assert np.all(np.abs(on) > 0.0)  # both steer: each has the other ahead, within range
    one_off = _terms(make_world(_pair(1.6, avoid=False)))
    assert np.all(one_off[0] == 0.0) and np.all(np.abs(one_off[1]) > 0.0)
    scene = _pair(1.6)
    scene["avoidance"] = {"enabled": False}
    world = make_world(scene)
    assert world.resource(Avoidance).enabled is False
    assert np.all(_terms(world) == 0.0)
    scene["avoidance"] = {"range": 0.2, "strength": 0.5}
    settings = make_world(scene).resource(Avoidance)
    assert (settings.enabled, settings.range, settings.strength) == (True, 0.2, 0.5)


def test_creatures_far_apart_move_exactly_as_without_avoidance(
    make_world: Callable[..., World],
) -> None:
    scene = _pair(6.0)
    scene["creatures"][0]["goals"] = [{"position": [-5.0, 1.0]}]  # away from each other
    scene["creatures"][1]["goals"] = [{"position": [5.0, -1.0]}]
    moved = make_world(scene)
    moved.step(90)
    scene["avoidance"] = {"enabled": False}
    straight = make_world(scene)
    straight.step(90)
    assert np.array_equal(moved.transforms.pos, straight.transforms.pos)


@pytest.mark.parametrize(
    ("key", "value", "message"),
    [
        ("enabled", "no", 'avoidance.enabled: must be a boolean, got "no"'),
        ("range", 0, "avoidance.range: must be in (0, 10], got 0"),
        ("strength", -1, "avoidance.strength: must be in [0, 10], got -1"),
        ("speed", 1, "avoidance.speed: unknown key (allowed: enabled, range, strength)"),
    ],
)
def test_a_bad_scene_value_is_one_line_naming_its_path(key: str, value: Any, message: str) -> None:
    scene = _pair(3.0)
    scene["avoidance"] = {key: value}
    with pytest.raises(SceneError) as caught:
        load_scene(scene)
    assert str(caught.value) == message


def test_a_bad_creature_value_is_one_line_naming_its_path() -> None:
    with pytest.raises(SceneError) as caught:
        load_scene(_pair(3.0, avoid="no"))
    assert str(caught.value) == 'creatures[0].avoid: must be a boolean, got "no"'


def contact_frames(world: World, frames: int) -> int:
    """Frames in which some two creatures' bodies are within the level of detail's contact
    margin of each other (the bounding spheres `world.lod` promotes by)."""
    proxies, margin = world.physics.proxies, world.lod.settings.contact_margin
    touching = 0
    for _ in range(frames):
        world.step()
        pos, _, centre, radius = proxies.sense(world.transforms)
        gaps = proxies.pair_gaps(pos, centre, radius, margin)[2]
        touching += bool((gaps < margin).any())
    return touching


def test_a_crossing_crowd_touches_less_with_avoidance(make_world: Callable[..., World]) -> None:
    scene = crowd_scene(16, seed=0)  # mirrored goals: the whole crowd crosses the middle
    frames = 330  # 5.5 s: without avoidance neighbours touch from about 4 s on
    steering = contact_frames(make_world(scene), frames)
    scene["avoidance"] = {"enabled": False}
    straight = contact_frames(make_world(scene), frames)
    assert straight > 0
    assert steering < straight


def test_the_kernel_gives_the_numpy_paths_term_bit_for_bit(monkeypatch: pytest.MonkeyPatch) -> None:
    """Many creatures packed close (pairs overlapping, behind and ahead, some not
    steering, some at their goal): the kernel's term and numpy's agree exactly."""
    assert KERNELS.get() is not None  # numba comes with the dev extra
    rng = np.random.default_rng(7)
    n = 60
    pos = rng.uniform(-2.0, 2.0, (n, 2))
    radius = rng.uniform(0.2, 0.6, n)
    angle = rng.uniform(0, 2 * np.pi, n)
    heading = np.stack([np.cos(angle), np.sin(angle)], axis=1)
    heading[::9] = 0.0  # going nowhere
    steering = rng.random(n) < 0.8
    to_goal = rng.uniform(0.0, 1.0, n)
    terms = []
    for backend in ("auto", "numpy"):
        monkeypatch.setattr(KERNELS, "backend", backend)
        terms.append(bend(pos, radius, heading, steering, to_goal, 0.5, 1.3))
    np.testing.assert_array_equal(*terms)
    assert np.count_nonzero(terms[0].any(axis=1)) > n // 2  # most are pushed


def test_a_crossing_crowd_moves_the_same_with_and_without_the_kernel(
    worlds_by_backend: ByBackend,
) -> None:
    kernel, numpy_path = worlds_by_backend(KERNELS, crowd_scene(8, seed=1), 120)
    terms = [w.resource(LocomotionStores).creatures.avoidance for w in (kernel, numpy_path)]
    np.testing.assert_array_equal(*terms)
    assert terms[0].any()  # they did steer around each other


def test_a_crowds_travel_targets_as_whole_arrays_are_the_gathered_ones(
    make_world: Callable[..., World],
) -> None:
    """Where most creatures are turned by avoidance (a crowd), their travel targets (where
    replayed creatures head) are found as whole-array math: the same bits as turning
    only the turned rows (`bent`), with the others at their steer point exactly and
    nan for no goal."""
    from ecs_tentacles.locomotion.plugin import LocomotionPlugin

    world = make_world(crowd_scene(12, seed=1, uniform=True))
    world.step(2)
    creatures = world.resource(LocomotionStores).creatures
    term = creatures.avoidance
    term[:] = np.random.default_rng(4).normal(0.0, 0.3, term.shape)
    term[[1, 5]] = 0.0  # straight on
    term[7, 0] = 0.0  # turned by one component only
    creatures.has_goal[3] = False
    steer = creatures.steer[:, :2]
    turned = np.flatnonzero(np.any(term != 0.0, axis=1))
    mantle = world.transforms.pos[world.creatures.mantle_row[turned], :2]
    gathered = steer.copy()
    gathered[turned] = mantle + bent(gathered[turned] - mantle, term[turned])
    gathered[3] = np.nan
    found = LocomotionPlugin()._travel_targets(world)  # most rows turned: whole arrays
    np.testing.assert_array_equal(found, gathered)
    np.testing.assert_array_equal(found[[1, 5]], steer[[1, 5]])
    assert not (found[[0, 2, 7]] == steer[[0, 2, 7]]).all(axis=1).any()
