"""The herding game's rules: penning wins, the clock loses, restart is exact, inputs replay."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from numpy.testing import assert_array_equal

from ecs_tentacles.herding.events import CreaturePenned, GameLost, GameWon
from ecs_tentacles.herding.game import HerdingGame
from ecs_tentacles.herding.play import Replay, play
from ecs_tentacles.world import World
from tests.herding.levels import level


def _state(world: World) -> list[np.ndarray]:
    groups = world.physics.views
    physics = [a for g in groups for a in (g.data.qpos, g.data.qvel, g.integration_state())]
    game = world.resource(HerdingGame).state
    return [
        np.array(a, copy=True)
        for a in (*physics, world.transforms.pos, world.motors.target, game.predator, game.aim)
    ] + [np.array([game.frames, len(game.penned), world.frame])]


class Scripted:
    """Walks the predator up behind creature `a` (west of it) and keeps pushing east."""

    def decide(self, world: World, game: HerdingGame) -> tuple[float, float]:
        row = world.creatures.mantle_row[0]
        x, y = world.transforms.pos[row, :2]
        return (float(x) - 0.7, float(y))


def test_penning_the_creatures_needed_wins_and_stops_the_clock() -> None:
    heard: list[Any] = []
    with World.from_scene(level(need=1, seconds=30)) as world:
        world.events.on(CreaturePenned, heard.append)
        world.events.on(GameWon, heard.append)
        world.events.on(GameLost, heard.append)
        result = play(world, Scripted())
        game = world.resource(HerdingGame)
        assert result["outcome"] == "won" and result["penned"] == 1, result
        assert 0 < result["seconds"] < 30
        assert [type(e) for e in heard] == [CreaturePenned, GameWon]
        assert heard[0].creature == world.creature("a")
        clock = game.elapsed
        world.step(30)
        assert game.elapsed == clock and game.outcome == "won"  # over: the clock stopped


def test_the_clock_running_out_loses() -> None:
    lost: list[GameLost] = []
    with World.from_scene(level(need=2, seconds=5)) as world:
        world.events.on(GameLost, lost.append)
        game = world.resource(HerdingGame)
        world.step(5 * 60 - 1)
        assert game.outcome == "playing" and game.left == pytest.approx(1 / 60)
        world.step(1)
        assert game.outcome == "lost" and game.left == 0.0
        assert len(lost) == 1 and lost[0].need == 2 and lost[0].penned == 0
        world.step(10)
        assert len(lost) == 1


def test_restart_restores_the_level_bit_for_bit_as_a_fresh_load() -> None:
    with World.from_scene(level()) as fresh, World.from_scene(level()) as played:
        game = played.resource(HerdingGame)
        game.aim(played, (-0.5, 0.3))
        played.step(90)
        assert game.state.frames == 90 and not np.array_equal(game.predator, [-1.5, 0.0])
        game.restart(played)
        for a, b in zip(_state(played), _state(fresh), strict=True):
            assert_array_equal(a, b)
        assert game.state.log == [] and game.outcome == "playing"
        for world in (played, fresh):  # and they go on alike
            world.resource(HerdingGame).aim(world, (-0.6, -0.2))
            world.step(60)
        for a, b in zip(_state(played), _state(fresh), strict=True):
            assert_array_equal(a, b)


def test_a_recorded_input_log_replays_to_the_same_game() -> None:
    with World.from_scene(level(need=1, seconds=30)) as world:
        first = play(world, Scripted())
        end = _state(world)
    with World.from_scene(level(need=1, seconds=30)) as world:
        again = play(world, Replay(first["log"], first["runs"]))
        assert {k: again[k] for k in ("outcome", "penned", "seconds")} == {
            k: first[k] for k in ("outcome", "penned", "seconds")
        }
        assert again["log"] == first["log"]
        for a, b in zip(_state(world), end, strict=True):
            assert_array_equal(a, b)


def test_the_predator_is_a_danger_creatures_flee_and_fear() -> None:
    from ecs_tentacles.behaviour import dangers

    with World.from_scene(level()) as world:
        positions, owners = dangers(world)
        assert_array_equal(positions[:, :2], [[-1.5, 0.0]]) and owners.tolist() == [-1]
        game = world.resource(HerdingGame)
        game.aim(world, (-0.4, 0.0))  # 0.4 m west of creature a
        world.step(120)
        a = world.transforms.pos[world.creatures.mantle_row[0], :2]
        assert a[0] > 0.05  # crawled away east


def test_an_aim_that_is_not_a_point_is_refused() -> None:
    with World.from_scene(level()) as world:
        with pytest.raises(ValueError, match="aim"):
            world.resource(HerdingGame).aim(world, (float("nan"), 0.0))
