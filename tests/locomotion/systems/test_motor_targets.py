"""motor_targets: action poses, easing, travelling waves and writhing gains."""

from __future__ import annotations

import argparse
from collections.abc import Callable

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from ecs_tentacles.components import Creature
from ecs_tentacles.creator.crowd import crowd_scene
from ecs_tentacles.locomotion.actions import (
    STRENGTH,
    ActionQueue,
    ActionQueues,
    Kind,
    make_action,
)
from ecs_tentacles.locomotion.grip import sucker_points
from ecs_tentacles.locomotion.params import Locomotion
from ecs_tentacles.locomotion.systems.motor_targets import (
    KERNELS,
    LIFT,
    SMOOTHING_SECONDS,
    MotorTargets,
    _links_of,
)
from ecs_tentacles.world import World
from tests.conftest import ByBackend, creature_scene


def _links(world: World, tentacle: int) -> np.ndarray:
    first = int(world.tentacles.first_link[tentacle])
    return np.arange(first, first + int(world.tentacles.links[tentacle]))


def _rest_pitch(world: World, tentacle: int) -> np.ndarray:
    """Link pitches at rest: a droop along the tentacle that lays its underside flat."""
    return 2.0 * world.tentacles.rest_pitch[tentacle] * world.motors.arc[_links(world, tentacle)]


def _rest_targets(world: World) -> np.ndarray:
    """(curl, sweep) of every link at rest: curls turn each link by its pitch change."""
    curl = np.concatenate(
        [np.diff(_rest_pitch(world, k), prepend=0.0) for k in range(len(world.tentacles))]
    )
    return np.stack([curl, np.zeros_like(curl)], axis=1)


def _eased(start: np.ndarray, goal: np.ndarray, frames: int, dt: float) -> np.ndarray:
    """Where a target starting at `start` is after easing toward `goal` for `frames`."""
    keep = np.exp(-dt / SMOOTHING_SECONDS) ** frames
    return goal + (start - goal) * keep


def test_idle_targets_ease_to_rest_without_waves(make_world: Callable[..., World]) -> None:
    world = make_world(creature_scene(count=2, links=4))
    octo = world.creature("octo")
    world.step(20)  # waving: the targets are off zero
    start = world.motors.target.copy()
    assert np.abs(start[:, :2]).min() > 1e-4
    assert_array_equal(start[:, 2], 0.0)
    world.resource(Locomotion).set(octo, wave_amplitude=0.0, writhe=0.0)
    # an exponential ease with the smoothing time constant, no jump
    rest = _rest_targets(world)
    assert (rest[:, 0] > 0).all() and (rest[:, 0] < 0.1).all()  # a gentle droop
    dt = world.settings.dt
    done = 0
    for frames in (1, 5, 30):
        world.step(frames - done)
        done = frames
        expected = _eased(start[:, :2], rest, frames, dt)
        assert_allclose(world.motors.target[:, :2], expected, rtol=1e-12, atol=1e-15)
    world.step(90)
    assert_allclose(world.motors.target[:, :2], rest, atol=1e-8)
    assert_array_equal(world.motors.target[:, 2], 0.0)
    assert world.resource(Locomotion).actions(octo) == ["idle", "idle"]


def test_idle_gain_is_the_same_before_and_after_a_drive(
    make_world: Callable[..., World],
) -> None:
    # an idle tentacle writhes at STRENGTH[IDLE] whether or not it has driven yet
    world = make_world(creature_scene(count=2, links=3))
    octo = world.creature("octo")
    world.resource(Locomotion).set(octo, writhe=0.0)
    ActionQueues(world).replace(1, [make_action(Kind.DETACH, 10.0)])  # short, then idle again
    world.step(3)
    assert world.resource(Locomotion).actions(octo) == ["idle", "idle"]
    assert_allclose(world.motors.gain, STRENGTH[Kind.IDLE], rtol=1e-15)


def _arch(world: World, tentacle: int, angle: float) -> None:
    """Hold `tentacle` in a compress of `angle` for ever, with nothing queued after it."""
    creature = world.component(world.creature("octo"), Creature)
    world.component(creature.tentacles[tentacle], ActionQueue).clear()
    t = world.stores["locomotion.tentacles"]
    t.action[tentacle] = Kind.COMPRESS
    t.action_angle[tentacle] = angle
    t.action_strength[tentacle] = STRENGTH[Kind.COMPRESS]
    t.orient[tentacle] = 0.0
    t.duration[tentacle] = np.inf


@pytest.mark.parametrize("angle", [0.3, np.radians(50)])
def test_compress_arches_the_tentacle(make_world: Callable[..., World], angle: float) -> None:
    # no goal, so tentacle selection leaves the tentacle alone
    world = make_world(creature_scene(count=2, links=6))
    octo = world.creature("octo")
    world.resource(Locomotion).set(octo, wave_amplitude=0.0, writhe=0.0)
    world.step(3)
    start = world.motors.target.copy()
    _arch(world, 0, angle)
    world.step(30)
    links = _links(world, 0)
    pitch = -angle * np.sin(2 * np.pi * world.motors.arc[links]) + LIFT[Kind.COMPRESS]
    pitch += _rest_pitch(world, 0)
    curl = np.diff(pitch, prepend=0.0)  # each joint turns by its link's pitch change
    dt = world.settings.dt
    assert_allclose(
        world.motors.target[links, 0], _eased(start[links, 0], curl, 30, dt), atol=1e-15
    )
    assert_allclose(world.motors.target[links, 1:], 0.0, atol=1e-6)  # no sweep, no twist
    world.step(30)
    assert_allclose(world.motors.target[links, 0], curl, atol=1e-7)
    # the link pitches: up from a flat base, highest mid-way, down to a flat tip
    assert_allclose(np.cumsum(world.motors.target[links, 0]), pitch, atol=1e-7)
    assert world.resource(Locomotion).actions(octo) == ["compress", "idle"]
    # the other tentacle stays at rest
    other = _links(world, 1)
    assert_allclose(world.motors.target[other, :2], _rest_targets(world)[other], atol=1e-7)
    assert_allclose(world.motors.gain[links], STRENGTH[Kind.COMPRESS], rtol=1e-15)


def test_arched_tentacle_is_shorter(make_world: Callable[..., World]) -> None:
    world = make_world(creature_scene(count=2, links=6))
    octo = world.creature("octo")
    world.resource(Locomotion).set(octo, wave_amplitude=0.0, writhe=0.0)
    tip = int(world.tentacles.tip_sucker[0])
    mantle = world.creatures.mantle_row[0]
    world.step(30)
    straight = np.linalg.norm(sucker_points(world)[tip, :2] - world.transforms.pos[mantle, :2])
    _arch(world, 0, np.radians(50))
    world.step(60)
    arched = np.linalg.norm(sucker_points(world)[tip, :2] - world.transforms.pos[mantle, :2])
    assert arched < straight - 0.02


def test_gain_is_the_action_strength_without_writhing(make_world: Callable[..., World]) -> None:
    world = make_world(creature_scene(count=2, links=4))
    octo = world.creature("octo")
    world.resource(Locomotion).set(octo, writhe=0.0)
    _arch(world, 1, 0.5)
    gains = []
    for _ in range(20):
        world.step(1)
        gains.append(world.motors.gain[_links(world, 1)].copy())
    assert_allclose(np.array(gains), STRENGTH[Kind.COMPRESS], rtol=1e-15)


def test_writhing_modulates_the_gain_in_time(make_world: Callable[..., World]) -> None:
    world = make_world(creature_scene(count=2, links=4))
    octo = world.creature("octo")
    world.resource(Locomotion).set(octo, writhe=0.5, wave_frequency=1.0)
    _arch(world, 0, 0.5)
    links = _links(world, 0)
    samples = []
    for _ in range(60):  # one period of the wave
        world.step(1)
        samples.append(world.motors.gain[links].copy())
    gains = np.array(samples)
    strength = STRENGTH[Kind.COMPRESS]
    assert gains.min() >= strength * 0.5 - 1e-12
    assert gains.max() <= strength * 1.5 + 1e-12
    # every link swings through nearly the whole range within a period, around the strength
    assert_allclose(gains.max(axis=0), strength * 1.5, rtol=2e-3)
    assert_allclose(gains.min(axis=0), strength * 0.5, rtol=4e-3)
    assert_allclose(gains.mean(axis=0), strength, rtol=1e-9)


def test_the_links_of_simulated_creatures_are_every_motor_row_they_own(
    make_world: Callable[..., World],
) -> None:
    world = make_world(crowd_scene(24, seed=2))  # 8 body plans: 3 to 8 tentacles, links vary
    world.despawn(int(world.creatures.entity[5]))  # rows renumbered
    rng = np.random.default_rng(0)
    for _ in range(10):
        replayed = rng.random(len(world.creatures)) < 0.7
        owned = ~replayed[world.tentacles.creature_row[world.motors.tentacle_row]]
        live_tentacles = np.flatnonzero(~replayed[world.tentacles.creature_row])
        assert_array_equal(_links_of(world, live_tentacles), np.flatnonzero(owned))


def test_an_inner_links_previous_is_the_entry_before_it(make_world: Callable[..., World]) -> None:
    world = make_world(crowd_scene(24, seed=2))
    rng = np.random.default_rng(1)
    for _ in range(5):
        replayed = rng.random(len(world.creatures)) < 0.6
        links = _links_of(world, np.flatnonzero(~replayed[world.tentacles.creature_row]))
        first = world.tentacles.first_link[world.motors.tentacle_row[links]]
        inner = np.flatnonzero(links != first)
        assert_array_equal(links[inner - 1], links[inner] - 1)  # the link before, in `links`


def _motor_targets(world: World) -> MotorTargets:
    return next(s for s in world.schedule if isinstance(s, MotorTargets))


@pytest.mark.parametrize("follow", [False, True])
def test_the_kernels_give_the_numpy_paths_targets_bit_for_bit(
    make_world: Callable[..., World], follow: bool, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Every link, and whole tentacles of some creatures (the others replayed); on the
    plane and with a ground-follow droop per tentacle (terrain)."""
    assert KERNELS.get() is not None  # numba comes with the dev extra
    world = make_world(crowd_scene(24, seed=2))  # 8 body plans; strokes, grips, waves
    world.step(60)
    system = _motor_targets(world)
    rng = np.random.default_rng(3)
    if follow:
        system.follow = rng.uniform(-0.8, 0.8, len(world.tentacles))
    start = system.eased.copy(), world.motors.target.copy(), world.motors.gain.copy()
    replayed = rng.random(len(world.creatures)) < 0.5
    some = _links_of(world, np.flatnonzero(~replayed[world.tentacles.creature_row]))
    for links in (slice(None), some):
        results = []
        for backend in ("auto", "numpy"):
            monkeypatch.setattr(KERNELS, "backend", backend)
            system.eased[:], world.motors.target[:], world.motors.gain[:] = start
            system._targets(world, world.settings.dt, links)
            motors = world.motors
            results.append((system.eased.copy(), motors.target.copy(), motors.gain.copy()))
        for kernel, numpy_path in zip(*results, strict=True):
            assert_array_equal(kernel, numpy_path)
        assert not np.array_equal(results[0][0], start[0])  # the targets moved


def test_a_crowd_moves_the_same_with_and_without_the_kernels(worlds_by_backend: ByBackend) -> None:
    worlds_by_backend(KERNELS, crowd_scene(6, seed=4), 90)


def test_the_ground_follow_kernel_reaches_numpys_points_bit_for_bit(
    make_world: Callable[..., World], monkeypatch: pytest.MonkeyPatch
) -> None:
    """The droop that lays tentacles onto terrain, with the mantles turned every way, a
    tentacle folded straight up its mantle's axis (nothing left to lay down) and one NaN
    pose: the kernel's reach points are numpy's."""
    from ecs_tentacles.cli.crowd import crowd_from_args
    from ecs_tentacles.ground import ground_of
    from ecs_tentacles.locomotion.systems.motor_targets import ground_follow

    args = argparse.Namespace(seed=2, spacing=None, idle=0.0, species=8, uniform=False)
    world = make_world(crowd_from_args(12, argparse.Namespace(**vars(args), terrain="rocky")))
    world.step(5)
    t, transforms = world.tentacles, world.transforms
    rng = np.random.default_rng(7)
    quat = rng.normal(size=(len(world.creatures), 4))
    transforms.quat[world.creatures.mantle_row] = quat / np.linalg.norm(quat, axis=1)[:, None]
    transforms.quat[world.creatures.mantle_row[0]] = [1.0, 0.0, 0.0, 0.0]
    base, tip = t.base_row[0], t.base_row[0] + t.links[0] - 1
    transforms.pos[tip] = transforms.pos[base] + [0.0, 0.0, 0.3]  # along the mantle's up
    transforms.pos[t.base_row[5]] = np.nan
    rows = np.arange(len(t))
    droops = []
    for backend in ("auto", "numpy"):
        monkeypatch.setattr(KERNELS, "backend", backend)
        droops.append(ground_follow(world, ground_of(world), rows))
    assert droops[0].tobytes() == droops[1].tobytes()
    assert np.isnan(droops[0][5]) and np.isfinite(np.delete(droops[0], 5)).all()
