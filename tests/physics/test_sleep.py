"""Still, idle creatures sleep (are not stepped) and wake when something changes."""

from __future__ import annotations

import json
from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.testing import assert_array_equal

from ecs_tentacles.components import Creature
from ecs_tentacles.host import Host
from ecs_tentacles.locomotion.goals import GoalBook
from ecs_tentacles.physics.registries import MotionWants
from ecs_tentacles.physics.sleep import SETTLE_FRAMES
from ecs_tentacles.plugin import Plugin
from ecs_tentacles.registry import App
from ecs_tentacles.world import World
from tests.conftest import NO_LOCOMOTION

RESTING = {"count": 3, "links": 5, "wave_amplitude_deg": 0, "writhe": 0}


def _scene(tentacles: dict[str, Any], **physics: Any) -> dict[str, Any]:
    creatures = [
        {"name": "rest", "position": [0.0, 0.0], "tentacles": tentacles},
        {"name": "busy", "position": [4.0, 0.0], "tentacles": {"count": 3, "links": 5}},
    ]
    return {"version": 1, "physics": physics, "creatures": creatures}


def test_a_still_idle_creature_sleeps_and_a_goal_wakes_it(
    make_world: Callable[..., World],
) -> None:
    world = make_world(_scene(RESTING))
    rest, busy = world.physics.groups
    world.step(240)  # settles on the ground, then lies still
    assert rest.sleeping and not busy.sleeping  # the writhing one never sleeps
    assert world.physics.sleep.asleep == 1
    assert json.dumps({"asleep": world.physics.sleep.asleep}) == '{"asleep": 1}'  # bench JSON
    state = rest.integration_state()
    world.step(30)
    assert_array_equal(rest.integration_state(), state)  # not stepped at all
    start = world.transforms.pos[rest.body_rows[0]].copy()
    world.resource(GoalBook).set(world.creature("rest"), [1.0, 0.0])
    world.step(1)
    assert not rest.sleeping
    world.step(120)
    assert np.linalg.norm(world.transforms.pos[rest.body_rows[0]] - start) > 0.01


def test_a_script_moving_a_servo_wakes_it(make_world: Callable[..., World]) -> None:
    # the script drives the servos (waves and writhing are locomotion's keys: none here)
    world = make_world(_scene({"count": 3, "links": 5}), plugins=NO_LOCOMOTION)
    rest = world.physics.groups[0]
    world.step(240)
    assert rest.sleeping
    world.motors.target[rest.actuator_motor_rows[0], 0] = -0.5
    world.step(1)
    assert not rest.sleeping
    assert np.abs(rest.data.qvel).max() > 1e-3


def test_sleep_can_be_switched_off(make_world: Callable[..., World]) -> None:
    world = make_world(_scene(RESTING, sleep=False))
    world.step(SETTLE_FRAMES + 240)
    assert world.physics.sleep.asleep == 0


class KeepAwake(Plugin):
    """Wants the creature called `name` to move (a user plugin's `MotionWants` entry)."""

    name = "keep_awake"

    def __init__(self, creature: str) -> None:
        super().__init__()
        self.creature = creature

    def build(self, app: App) -> None:
        app.add(MotionWants, self.keep)

    def keep(self, world: Host) -> np.ndarray:
        row = [c.row for _, c in world.query(Creature) if c.name == self.creature]
        wanted = np.zeros(len(world.creatures), dtype=bool)
        wanted[row] = True
        return wanted


class NoOpinion(Plugin):
    name = "no_opinion"  # no MotionWants entry, like most plugins


def test_a_plugin_that_wants_a_creature_to_move_keeps_it_awake(
    make_world: Callable[..., World],
) -> None:
    off = {"locomotion": False, "suckers": False}  # nothing drives either creature
    world = make_world(_scene({"count": 3, "links": 5}), plugins=off)
    world.add_plugin(KeepAwake("rest"))
    world.add_plugin(NoOpinion())
    rest, other = world.physics.groups  # no locomotion: nothing drives either one
    world.step(240)  # as long as it took to fall asleep above
    assert not rest.sleeping and other.sleeping
    assert np.abs(rest.data.qvel).max() < 1e-3  # still, yet stepped: someone wants it


def test_with_locomotion_off_no_goal_keeps_anyone_awake(
    make_world: Callable[..., World],
) -> None:
    off = {"locomotion": False, "suckers": False}  # its waves and writhing are keys no more
    world = make_world(_scene({"count": 3, "links": 5}), plugins=off)
    world.step(240)
    assert world.physics.groups[0].sleeping
