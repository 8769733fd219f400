"""Locomotion parameters changed at run time: checked, stored, reaching the servos."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from ecs_tentacles.components import Creature
from ecs_tentacles.locomotion.actions import BASE_SECONDS, ActionQueue, Kind
from ecs_tentacles.locomotion.params import Locomotion
from ecs_tentacles.world import World
from tests.conftest import creature_scene


def _world(make_world: Callable[..., World], gait: str = "coordinated", **creature: Any) -> World:
    scene = creature_scene(count=4, links=4)
    scene["creatures"][0]["locomotion"] = {"gait": gait}
    scene["creatures"][0].update(creature)
    return make_world(scene)


def _links(world: World, tentacle: int) -> np.ndarray:
    first = int(world.tentacles.first_link[tentacle])
    return np.arange(first, first + int(world.tentacles.links[tentacle]))


def _actuators(world: World, motor_rows: np.ndarray) -> np.ndarray:
    return np.flatnonzero(np.isin(world.physics.views[0].actuator_motor_rows, motor_rows))


def test_strength_of_one_tentacle_reaches_its_servos(make_world: Callable[..., World]) -> None:
    world = _world(make_world)
    octo = world.creature("octo")
    group = world.physics.views[0]
    world.step(1)
    before = group.kp.copy()
    world.resource(Locomotion).set(octo, tentacle=1, strength=40.0, damping=2.0)
    world.step(1)
    motors = world.motors
    links = _links(world, 1)
    base = _actuators(world, links[:1])
    assert len(base) == 2  # curl and sweep
    assert_allclose(group.kp[base], 40.0 * motors.gain[links[0]], rtol=1e-12)
    assert_allclose(group.kv[base], 2.0 * motors.gain[links[0]], rtol=1e-12)
    # every link of the tentacle, tapered by its scale
    rows = world.physics.views[0].actuator_motor_rows
    mine = _actuators(world, links)
    assert_allclose(
        group.kp[mine],
        40.0 * motors.scale[rows[mine]] * motors.gain[rows[mine]],
        rtol=1e-12,
    )
    # the other tentacles keep the scene's 25, times this frame's gain
    others = np.setdiff1d(np.arange(len(group.kp)), mine)
    assert_allclose(
        group.kp[others],
        25.0 * motors.scale[rows[others]] * motors.gain[rows[others]],
        rtol=1e-12,
    )
    assert not np.allclose(group.kp[mine], before[mine])
    assert world.resource(Locomotion).get(octo, 1)["strength"] == 40.0
    assert world.resource(Locomotion).get(octo, 1)["damping"] == 2.0
    assert world.resource(Locomotion).get(octo, 2)["strength"] == 25.0


def test_tentacle_parameters_land_in_the_tentacle_store(
    make_world: Callable[..., World],
) -> None:
    world = _world(make_world)
    octo = world.creature("octo")
    t = world.stores["locomotion.tentacles"]
    world.resource(Locomotion).set(octo, tentacle=2, speed=1.5, wave_amplitude=0.2, wavelength=2.0)
    world.resource(Locomotion).set(
        octo, writhe=0.9, wave_frequency=3.0, target_angle=1.0
    )  # all four
    assert t.speed.tolist() == [1.0, 1.0, 1.5, 1.0]
    assert_allclose(t.wave_amplitude, [np.radians(6)] * 2 + [0.2] + [np.radians(6)], rtol=1e-12)
    assert t.wavelength.tolist() == [0.7, 0.7, 2.0, 0.7]
    assert t.writhe.tolist() == [0.9] * 4
    assert t.wave_frequency.tolist() == [3.0] * 4
    assert t.target_angle.tolist() == [1.0] * 4
    gaits = world.stores["locomotion.creatures"]
    assert gaits.speed[0] == 1.0  # a tentacle's speed is not the creature's
    got = world.resource(Locomotion).get(octo, 2)
    assert got == {
        "speed": 1.5,
        "target_angle": 1.0,
        "strength": 25.0,
        "damping": 0.5,
        "wave_amplitude": 0.2,
        "wave_frequency": 3.0,
        "wavelength": 2.0,
        "writhe": 0.9,
        "gait": "coordinated",
        "creature_speed": 1.0,
        "drivers": 2,
    }


def test_gait_and_drivers_are_per_creature(make_world: Callable[..., World]) -> None:
    world = _world(make_world)
    octo = world.creature("octo")
    world.resource(Locomotion).set(octo, gait="cyclic")
    assert world.resource(Locomotion).get(octo)["gait"] == "cyclic"
    world.resource(Locomotion).set(octo, gait="coordinated", drivers=4)
    assert (
        world.resource(Locomotion).get(octo, 3)["gait"],
        world.resource(Locomotion).get(octo, 3)["drivers"],
    ) == (
        "coordinated",
        4,
    )
    assert world.stores["locomotion.creatures"].drivers[0] == 4


def test_gait_switch_changes_who_drives(make_world: Callable[..., World]) -> None:
    world = _world(make_world, goals=[{"position": [1.5, 0.0]}])
    octo = world.creature("octo")
    world.resource(Locomotion).set(octo, gait="cyclic")
    world.step(1)
    assert world.resource(Locomotion).queue(octo, 0) == ["extend", "attach", "pull", "detach"]


def _durations(world: World, tentacle: int) -> list[float]:
    creature = world.component(world.creature("octo"), Creature)
    pending = world.component(creature.tentacles[tentacle], ActionQueue).pending
    return [float(world.stores["locomotion.tentacles"].duration[tentacle])] + [
        a.duration for a in pending
    ]


def test_speeds_divide_the_durations_of_new_actions(make_world: Callable[..., World]) -> None:
    world = _world(make_world, gait="cyclic", goals=[{"position": [1.5, 0.0]}])
    octo = world.creature("octo")
    world.resource(Locomotion).set(octo, speed=2.0)
    world.resource(Locomotion).set(octo, tentacle=0, speed=1.25)
    world.step(1)
    kinds = [Kind.EXTEND, Kind.ATTACH, Kind.PULL, Kind.DETACH]
    assert _durations(world, 0) == [BASE_SECONDS[k] / 2.5 for k in kinds]
    assert world.resource(Locomotion).get(octo)["creature_speed"] == 2.0
    # a stroke under way keeps the durations it was queued with
    world.resource(Locomotion).set(octo, speed=4.0)
    world.step(1)
    assert _durations(world, 0) == [BASE_SECONDS[k] / 2.5 for k in kinds]


def test_numpy_numbers_are_numbers(make_world: Callable[..., World]) -> None:
    # values straight from numpy arrays (sliders, scripts) are accepted like Python numbers
    world = _world(make_world)
    octo = world.creature("octo")
    world.resource(Locomotion).set(octo, tentacle=1, writhe=np.float32(0.5), speed=np.int64(2))
    world.resource(Locomotion).set(octo, drivers=np.int64(3))
    got = world.resource(Locomotion).get(octo, 1)
    assert (got["writhe"], got["speed"], got["drivers"]) == (0.5, 2.0, 3)


@pytest.mark.parametrize(
    ("params", "message"),
    [
        ({"speed": -1}, r"speed: must be in [0.01, 10], got -1"),
        ({"speed": 0}, r"speed: must be in [0.01, 10], got 0"),
        ({"speed": 10.5}, r"speed: must be in [0.01, 10], got 10.5"),
        ({"speed": float("nan")}, r"speed: must be a finite number, got nan"),
        ({"speed": "fast"}, r"speed: must be a number, got 'fast'"),
        ({"writhe": True}, r"writhe: must be a number, got True"),
        ({"writhe": 1.5}, r"writhe: must be in [0, 1], got 1.5"),
        ({"strength": -0.1}, r"strength: must be in [0, 1000], got -0.1"),
        ({"damping": float("inf")}, r"damping: must be a finite number, got inf"),
        ({"wave_amplitude": 2.0}, r"wave_amplitude: must be in [0, 1.0472], got 2.0"),
        ({"wavelength": 0.0}, r"wavelength: must be in [0.01, 10], got 0.0"),
        ({"target_angle": -0.5}, r"target_angle: must be in [0, 1.5708], got -0.5"),
        ({"wave_frequency": 21}, r"wave_frequency: must be in [0, 20], got 21"),
        ({"gait": "gallop"}, r"gait: must be one of cyclic, coordinated, got 'gallop'"),
        ({"drivers": 0}, r"drivers: must be a whole number in [1, 4], got 0"),
        ({"drivers": 5}, r"drivers: must be a whole number in [1, 4], got 5"),
        ({"drivers": 2.0}, r"drivers: must be a whole number in [1, 4], got 2.0"),
        ({"drivers": True}, r"drivers: must be a whole number in [1, 4], got True"),
        ({"colour": 1}, r"colour: unknown parameter (allowed: damping, drivers, gait, "),
        ({"strength": 1e5}, r"strength: must be in [0, 1000], got 100000.0"),
        (
            {"strength": 500},
            r"strength: strength 500 needs damping >= 1.04 at this world's physics step"
            r" (2.08 ms), got damping 0.5",
        ),
        (
            {"damping": 0.0},
            r"damping: strength 25 needs damping >= 0.0521 at this world's physics step"
            r" (2.08 ms), got damping 0",
        ),
    ],
)
def test_bad_values_name_the_parameter(
    make_world: Callable[..., World], params: dict[str, Any], message: str
) -> None:
    world = _world(make_world)
    octo = world.creature("octo")
    with pytest.raises(ValueError) as raised:
        world.resource(Locomotion).set(octo, **params)
    assert str(raised.value).startswith(message)


def test_nothing_changes_when_one_value_is_bad(make_world: Callable[..., World]) -> None:
    world = _world(make_world)
    octo = world.creature("octo")
    before = world.resource(Locomotion).get(octo, 1)
    for params in (
        {"speed": 2.0, "writhe": 5.0},
        {"gait": "cyclic", "drivers": 9},
        {"drivers": 1, "gait": "trot"},
        {"strength": 3.0, "wavelength": -1.0},
        {"writhe": 0.5, "colour": 2},
    ):
        with pytest.raises(ValueError):
            world.resource(Locomotion).set(octo, **params)
        assert world.resource(Locomotion).get(octo, 1) == before, params
    assert_array_equal(world.motors.strength[_links(world, 1)], 25.0 * world.motors.scale[:4])


@pytest.mark.parametrize("tentacle", [-1, 4, 10])
def test_tentacle_index_out_of_range(make_world: Callable[..., World], tentacle: int) -> None:
    world = _world(make_world)
    octo = world.creature("octo")
    message = rf"^tentacle: must be in \[0, 3\], got {tentacle}$"
    with pytest.raises(ValueError, match=message):
        world.resource(Locomotion).set(octo, tentacle=tentacle, writhe=0.5)
    with pytest.raises(ValueError, match=message):
        world.resource(Locomotion).get(octo, tentacle)
    with pytest.raises(ValueError, match=message):
        world.resource(Locomotion).queue(octo, tentacle)


@pytest.mark.parametrize(("params"), [{"gait": "cyclic"}, {"drivers": 1}])
def test_creature_parameters_refuse_a_tentacle_index(
    make_world: Callable[..., World], params: dict[str, Any]
) -> None:
    world = _world(make_world)
    octo = world.creature("octo")
    name = next(iter(params))
    with pytest.raises(ValueError, match=rf"^{name}: is set per creature$"):
        world.resource(Locomotion).set(octo, tentacle=0, **params)
    assert world.resource(Locomotion).get(octo)["gait"] == "coordinated"
    assert world.resource(Locomotion).get(octo)["drivers"] == 2


def test_actions_lists_each_tentacle(make_world: Callable[..., World]) -> None:
    world = _world(make_world, goals=[{"position": [-1.5, 0.0]}])
    octo = world.creature("octo")
    assert world.resource(Locomotion).actions(octo) == ["idle"] * 4
    world.step(1)
    assert world.resource(Locomotion).actions(octo) == ["idle", "idle", "orient", "idle"]


def test_a_stiffer_servo_needs_more_damping(make_world: Callable[..., World]) -> None:
    world = _world(make_world)  # 60 fps x 8 substeps: a physics step of 1/480 s
    octo = world.creature("octo")
    assert world.resource(Locomotion).strength_limit(octo) == pytest.approx(0.5 * 480)
    world.resource(Locomotion).set(octo, tentacle=2, strength=1000.0, damping=1000.0 / 480)
    assert world.resource(Locomotion).get(octo, 2)["strength"] == 1000.0
    assert world.resource(Locomotion).strength_limit(octo, 2) == 1000.0  # the schema's ceiling
    assert world.resource(Locomotion).strength_limit(octo) == pytest.approx(240.0)  # the others'
