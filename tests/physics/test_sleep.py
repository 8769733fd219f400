"""Still, idle creatures sleep (are not stepped) and wake when something changes."""

from __future__ import annotations

import json
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
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
    rest, busy = world.physics.views
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
    rest = world.physics.views[0]
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
    rest, other = world.physics.views  # no locomotion: nothing drives either one
    world.step(240)  # as long as it took to fall asleep above
    assert not rest.sleeping and other.sleeping
    assert np.abs(rest.data.qvel).max() < 1e-3  # still, yet stepped: someone wants it


def test_with_locomotion_off_no_goal_keeps_anyone_awake(
    make_world: Callable[..., World],
) -> None:
    off = {"locomotion": False, "suckers": False}  # its waves and writhing are keys no more
    world = make_world(_scene({"count": 3, "links": 5}), plugins=off)
    world.step(240)
    assert world.physics.views[0].sleeping


def test_the_sleep_kernel_decides_as_numpy_bit_for_bit(
    make_world: Callable[..., World], monkeypatch: pytest.MonkeyPatch
) -> None:
    """Every way a creature stays awake or falls asleep, decided by the kernel and by
    numpy from the same state: the same counters, commands and sleepers."""
    from ecs_tentacles.creator.crowd import crowd_scene
    from ecs_tentacles.physics import sleep as sleep_module

    world = make_world(crowd_scene(12, seed=1, uniform=True))
    world.step(2)
    physics, sleep = world.physics, world.physics.sleep
    batch = physics.batches[0]
    rows = len(batch.members)
    assert rows == 12 and len(batch.equality_ids)
    rng = np.random.default_rng(5)
    qvel = batch.qvel
    qvel[:] = rng.uniform(-1e-4, 1e-4, qvel.shape)  # still
    qvel[5, 3] = 0.5  # calm but moving
    qvel[6, 2] = np.nan  # calm, a NaN speed: numpy's max and >= call it not moving,
    qvel[6, 5] = 0.5  # even beside a fast joint
    for creature, previous in zip(batch.members, sleep.commands[0], strict=True):
        previous[:] = np.concatenate([batch.ctrl[physics.row_of[creature]],
                                      batch.kp[physics.row_of[creature]]])  # fmt: skip
    sleep.commands[0][7, 1] += 1.0  # its commands changed
    sleep.commands[0][8, -1] = np.nan  # unknown last gain: changed
    start_known = np.ones(rows, dtype=bool)
    start_known[batch.members[9]] = False  # its last commands unknown
    proxies = np.zeros(rows, dtype=np.int64)
    proxies[batch.members[1]] = 2  # someone near
    attached = np.zeros(len(world.suckers.attached), dtype=bool)
    attached[batch.sucker_rows[2, 0]] = True  # a sucker holds
    # creatures' store rows not their physics order (as after a despawn elsewhere)
    monkeypatch.setattr(physics.roster, "creature_row", physics.roster.creature_row[::-1].copy())
    wants = np.zeros(len(world.creatures), dtype=bool)
    wants[physics.roster.creature_row[batch.members[3]]] = True  # a plugin wants it to move
    still = np.full(rows, SETTLE_FRAMES - 1)  # one more still frame: asleep
    still[batch.members[10]] = 4
    sleeping = np.zeros(rows, dtype=bool)
    sleeping[batch.members[11]] = True
    physics.frozen[batch.members[4]] = True  # not commanded: untouched
    monkeypatch.setattr(world.suckers, "attached", attached)
    decided = []
    for backend in ("auto", "numpy"):
        monkeypatch.setattr(sleep_module.KERNELS, "backend", backend)
        saved = [c.copy() for c in sleep.commands]
        sleep.known[:], sleep.still[:] = start_known, still
        physics.proxies_used[:], physics.sleeping[:] = proxies, sleeping
        sleep.update(world, wants)
        decided.append([sleep.known.copy(), sleep.still.copy(), physics.sleeping.copy(),
                        *[c.copy() for c in sleep.commands]])  # fmt: skip
        sleep.commands = saved
    for kernel, numpy_path in zip(*decided, strict=True):
        assert kernel.tobytes() == numpy_path.tobytes()
    known, counted, asleep = decided[0][:3]
    by_row = counted[batch.members]
    assert by_row[[1, 2, 3, 7, 8, 9, 5]].tolist() == [0] * 7  # awake, count restarted
    assert by_row[4] == SETTLE_FRAMES - 1 and not asleep[batch.members[4]]  # frozen: as it was
    assert known.all()  # every commanded one's commands known now; the frozen one's were
    assert asleep[batch.members[[0, 6]]].all() and by_row[10] == 5  # calm and still: counted
    assert asleep[batch.members[11]] and by_row[11] == SETTLE_FRAMES - 1  # asleep: stays
