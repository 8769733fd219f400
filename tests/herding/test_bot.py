"""The bot proves every level winnable: it wins each headless with time to spare, and
plays the same game twice."""

from __future__ import annotations

import pytest

from ecs_tentacles.herding.play import Bot, play
from ecs_tentacles.scene.load import bundled_scene
from ecs_tentacles.world import World

SPARE = 0.15  # the share of the level's time the bot has left at least


@pytest.mark.slow  # each level is minutes of game: `pytest -m slow tests/herding`
@pytest.mark.parametrize("name", ["herding_1_field", "herding_2_shore", "herding_3_maze"])
def test_the_bot_wins_the_level_headless_with_time_to_spare(name: str) -> None:
    with World.from_scene(bundled_scene(name)) as world:
        result = play(world, Bot())
    assert result["outcome"] == "won", result
    assert result["penned"] >= result["need"]
    assert result["left"] >= SPARE * (result["seconds"] + result["left"]), result
