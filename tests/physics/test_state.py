"""The physics owns its state: `world.physics.state()` / `set_state()` bring back every
group, the health check and the sleep counters, so a world goes on as it would have."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.testing import assert_array_equal

from ecs_tentacles.locomotion.goals import GoalBook
from ecs_tentacles.world import World
from tests.conftest import crawlers

CRAWLERS = crawlers(2, apart=4.0, links=5)
RESTING: dict[str, Any] = {
    "version": 1,
    "creatures": [
        {
            "name": "rest",
            "position": [0.0, 0.0],
            "tentacles": {"count": 3, "links": 5, "wave_amplitude_deg": 0, "writhe": 0},
        }
    ],
}


def _blow_up(world: World) -> None:
    world.physics.views[1].data.qvel[7] = np.nan


def test_set_state_forgets_a_recovery_and_the_clock_since(
    make_world: Callable[..., World],
) -> None:
    world = make_world(CRAWLERS)
    world.step(30)
    saved = world.physics.state()
    before = [g.integration_state() for g in world.physics.views]
    _blow_up(world)
    world.step(12)
    health = world.physics.health
    assert health.recoveries == 1 and health.causes == {"mujoco": 1}
    assert world.physics.views[1].soften < 1.0  # servos soft after the recovery
    world.physics.set_state(saved)
    assert health.recoveries == 0 and health.causes == {}
    assert world.physics.time == saved.time
    for group, state in zip(world.physics.views, before, strict=True):
        assert_array_equal(group.integration_state(), state)
        assert group.soften == 1.0 and not group.frozen
    world.step(12)  # the saved state was copied: it goes back the same way again
    world.physics.set_state(saved)
    assert_array_equal(world.physics.views[1].integration_state(), before[1])


def test_a_restored_blow_up_recovers_the_same_way(make_world: Callable[..., World]) -> None:
    world = make_world(CRAWLERS)
    recovered: list[str] = []
    world.events.on("creature_recovered", lambda **e: recovered.append(e["cause"]))
    world.step(30)
    snap = world.snapshot()
    runs = []
    for _ in range(2):
        _blow_up(world)
        world.step(40)
        runs.append((world.transforms.pos.copy(), world.physics.health.recoveries))
        world.restore(snap)
    assert_array_equal(runs[0][0], runs[1][0])
    assert runs[0][1] == runs[1][1] == 1
    assert len(recovered) == 2 and recovered[0] == recovered[1]  # the same MuJoCo warnings


def test_a_sleeping_creature_is_asleep_again_after_set_state(
    make_world: Callable[..., World],
) -> None:
    world = make_world(RESTING)
    rest = world.physics.views[0]
    world.step(240)
    assert rest.sleeping
    saved = world.physics.state()
    still = world.physics.sleep.still.copy()
    world.resource(GoalBook).set(world.creature("rest"), [1.0, 0.0])
    world.step(20)
    assert not rest.sleeping and world.physics.sleep.still[0] == 0
    world.physics.set_state(saved)
    assert rest.sleeping
    assert_array_equal(world.physics.sleep.still, still)


def test_the_physics_systems_run_with_every_plugin_off(
    make_world: Callable[..., World],
) -> None:
    off = {"locomotion": False, "suckers": False, "threats": False, "fur": False, "clips": False}
    body_only = {"version": 1, "creatures": [{"tentacles": {"count": 3, "links": 5}}]}
    world = make_world(body_only, plugins=off)  # waves and writhing are locomotion's keys
    assert world.schedule.names == ["physics", "physics_sync", "physics_health"]
    assert {system.plugin for system in world.schedule} == {"core"}
    start = world.transforms.pos.copy()
    world.step(10)
    assert not np.array_equal(world.transforms.pos, start)  # it settles under gravity
