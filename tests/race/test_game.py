"""A race end to end without a window: the runner goes where it is steered and wins at
the flag; a rival there first, or the clock, loses it; a race replays exactly and
restarts from its start."""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

import numpy as np
import pytest

from ecs_tentacles.behaviour import travel
from ecs_tentacles.game.rules import playing
from ecs_tentacles.race.events import RaceFinished
from ecs_tentacles.race.game import NOBODY, RaceGame
from ecs_tentacles.race.play import Replay, play
from ecs_tentacles.world import World
from tests.race.levels import level


class Straight:
    """Steers the runner to a waypoint beside the flag, then to the flag, once."""

    def __init__(self) -> None:
        self.done = False

    def decide(self, world, race):  # type: ignore[no-untyped-def]
        if self.done:
            return None
        self.done = True
        return [(-0.75, 0.3), (0.0, 0.0)]


@dataclass
class StraightRace:
    """The level raced once along `Straight`: what the race showed as it ended, and the
    world, left as the race left it (the replay test restarts it; nothing else reads it)."""

    world: World
    result: dict[str, Any]
    moved: np.ndarray
    path: list[Any]
    finished: list[tuple[str, int]]
    runner: int
    mode: str
    ended: bool
    reported_winner: str


@pytest.fixture(scope="module")
def straight_race() -> Iterator[StraightRace]:
    finished: list[RaceFinished] = []
    with World.from_scene(level(rivals_wait=600)) as world:
        world.events.on(RaceFinished, finished.append)
        race = world.resource(RaceGame)
        start = world.transforms.pos[world.creatures.mantle_row[0], :2].copy()
        result = play(world, Straight())
        moved = world.transforms.pos[world.creatures.mantle_row[0], :2] - start
        mode, ended = playing(world) or ("", None)
        events = [(event.outcome, event.winner) for event in finished]
        over = ended is not None and ended.ended
        winner = ended.report(mode)["winner"] if ended is not None else ""
        path = list(race.state.path)
        yield StraightRace(world, result, moved, path, events, race.runner, mode, over, winner)


def test_the_runner_follows_its_path_to_the_flag_and_wins(straight_race: StraightRace) -> None:
    result, moved = straight_race.result, straight_race.moved
    assert result["outcome"] == "won" and result["winner"] == "you", result
    assert 0 < result["seconds"] < 20 and moved[0] > 0.5  # it crawled toward the flag
    path = straight_race.path
    assert path == [] or len(path) == 1  # the waypoint was passed
    assert straight_race.finished == [("won", straight_race.runner)]
    assert straight_race.mode == "race" and straight_race.ended
    assert straight_race.reported_winner == "you"


def test_a_rival_at_the_flag_first_loses_the_race_and_the_clock_stops_it_too() -> None:
    with World.from_scene(level(rival_at=(0.0, 0.9))) as world:  # its line is clear
        result = play(world, Straight())
    assert (result["outcome"], result["winner"]) == ("lost", "other"), result
    with World.from_scene(level(seconds=5, rivals_wait=600)) as world:  # nobody moves
        race = world.resource(RaceGame)
        world.step(round(6 * world.settings.fps))
        assert (race.outcome, race.winner, race.elapsed) == ("lost", NOBODY, 5.0)


def test_the_rivals_wait_then_crawl_to_the_flag() -> None:
    with World.from_scene(level(rivals_wait=1.0)) as world:
        world.step(30)
        assert not travel(world).going(world)[1]  # waiting
        world.step(60)
        assert travel(world).going(world)[1]  # off to the flag
        goal = world.resource(RaceGame).flag
        assert np.allclose(goal, (0.0, 0.0))


def test_a_race_replays_exactly_from_its_inputs_and_restarts_from_its_start(
    straight_race: StraightRace,
) -> None:
    world, first = straight_race.world, straight_race.result
    race = world.resource(RaceGame)
    race.restart(world)
    assert (world.frame, race.outcome, race.state.log) == (0, "playing", [])
    with World.from_scene(level(rivals_wait=600)) as world:
        again = play(world, Replay(first["log"]))
    assert (again["outcome"], again["seconds"]) == (first["outcome"], first["seconds"])
