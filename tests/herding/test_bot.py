"""The bot proves level 1 winnable: it wins headless within the level's time."""

from __future__ import annotations

from ecs_tentacles.herding.play import Bot, play
from ecs_tentacles.scene.load import bundled_scene
from ecs_tentacles.world import World


def test_the_bot_wins_level_1_headless() -> None:
    with World.from_scene(bundled_scene("herding_1_field")) as world:
        result = play(world, Bot())
    assert result["outcome"] == "won", result
    assert result["penned"] >= result["need"] == 3
    assert result["seconds"] <= 60
