"""The race bot proves level 2 winnable: it plans round the wall, through the gap, and
takes the flag before the rival on the open side (a player who only clicks the flag
loses there: `python tools/race_bot.py --careless`)."""

from __future__ import annotations

from tests.tools.loader import load_tool


def test_the_bot_wins_the_wall_level_headless() -> None:
    bot = load_tool("race_bot")
    result = bot.run_level("race_2_wall")
    assert (result["outcome"], result["winner"]) == ("won", "you"), result
    assert result["left"] >= 0.15 * 120  # at least 15 % of the time left
    assert len(result["log"]) >= 2  # a path of more than one point: round the wall
