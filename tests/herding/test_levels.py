"""Progression: the levels in order, a win opens the next, par times and stars, and
`ecs-tentacles levels` lists them."""

from __future__ import annotations

import json

import pytest

from ecs_tentacles.cli import main
from ecs_tentacles.herding import best_times
from ecs_tentacles.herding.game import stars_for
from ecs_tentacles.herding.levels import levels, next_level

HERDING = ["herding_1_field", "herding_2_shore", "herding_3_maze"]


pytestmark = pytest.mark.usefixtures("data_folder")  # best times kept in the test's folder


def _herding() -> list:
    return [level for level in levels() if level.mode == "herding"]


def test_the_herding_levels_come_in_order_and_only_the_first_is_open() -> None:
    found = _herding()
    assert [level.scene for level in found] == HERDING
    assert [level.unlocked for level in found] == [True, False, False]
    assert all(level.best is None and level.stars == 0 for level in found)
    assert all(0 < level.par < level.seconds for level in found)


def test_a_win_opens_the_next_level_and_earns_stars() -> None:
    first = _herding()[0]
    best_times.record_win(first.title, first.par * 1.2)  # within 1.5x par: 2 stars
    found = _herding()
    assert [level.unlocked for level in found] == [True, True, False]
    assert found[0].best == pytest.approx(first.par * 1.2) and found[0].stars == 2
    assert next_level("herding_1_field") == found[1]
    assert next_level("herding_3_maze") is None


def test_stars_are_three_within_par_two_within_half_again_one_for_a_win() -> None:
    assert [stars_for(s, 60.0) for s in (30.0, 60.0, 61.0, 90.0, 91.0, 500.0)] == [
        3,
        3,
        2,
        2,
        1,
        1,
    ]


def test_the_levels_command_lists_them_with_json(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["levels", "--json"]) == 0
    rows = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    herding = [row for row in rows if row["mode"] == "herding"]
    assert [row["scene"] for row in herding] == HERDING
    assert set(herding[0]) >= {"title", "par", "best", "stars", "unlocked", "seconds", "need"}
    assert main(["levels"]) == 0
    text = capsys.readouterr().out
    assert "herding_2_shore" in text and "locked" in text and "par" in text
