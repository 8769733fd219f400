"""The predator walks and runs: running is faster, scares farther and tires; a winded
predator walks until it has rested."""

from __future__ import annotations

import numpy as np
import pytest

from ecs_tentacles.herding.game import RECOVERED, HerdingGame
from ecs_tentacles.world import World
from tests.herding.levels import level


def test_running_is_faster_scares_farther_and_tires_then_rests() -> None:
    scene = level(predator={"position": [-1.5, -3.0], "speed": 0.5})
    scene["game"]["predator"].update(run_speed=1.5, run_reach=2.5, stamina_s=2.0, recover_s=4.0)
    with World.from_scene(scene) as world:
        game = world.resource(HerdingGame)
        assert game.scare == game.reach
        game.aim(world, (-1.5, 50.0))
        world.step(60)
        walked = game.predator[1] + 3.0
        assert walked == pytest.approx(0.5, abs=0.02)
        game.run(world, True)
        assert game.scare == 2.5 and game.sprinting
        world.step(60)
        assert game.predator[1] + 3.0 - walked == pytest.approx(1.5, abs=0.03)
        assert game.state.stamina == pytest.approx(0.5, abs=0.02)
        world.step(61)  # run dry: winded, it walks though Shift is still held
        assert game.state.winded and not game.sprinting and game.scare == game.reach
        y = game.predator[1]
        world.step(60)
        assert game.predator[1] - y == pytest.approx(0.5, abs=0.02)
        assert game.state.stamina == pytest.approx(0.25, abs=0.01)
        rested = 0
        while not game.sprinting:  # rested to RECOVERED: it runs again
            world.step(1)
            rested += 1
        assert rested == pytest.approx(60 * 4.0 * (RECOVERED - 0.25), abs=2)
        assert game.state.runs == [(60, True)]


def test_a_run_replays_from_the_log() -> None:
    from ecs_tentacles.herding.play import Replay, play

    class Runner:
        def decide(self, world: World, game: HerdingGame) -> tuple[float, float]:
            game.run(world, world.frame % 120 < 60)
            return (0.0, -3.0)

    scene = level(seconds=5)
    with World.from_scene(scene) as world:
        first = play(world, Runner())
        end = world.resource(HerdingGame).predator.copy()
    with World.from_scene(scene) as world:
        play(world, Replay(first["log"], first["runs"]))
        np.testing.assert_array_equal(world.resource(HerdingGame).predator, end)
