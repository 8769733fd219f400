"""`run` and `play --headless` stop once a level's game is won or lost and report the
game in `--json` (before, `run` went on to the last frame and `play` said nothing of
the game)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from ecs_tentacles.cli import main
from tests.race.levels import level


def won_soon(tmp_path: Path) -> Path:
    """A level the runner wins by itself: it starts beside the flag with a goal in it."""
    scene = level(at=(-0.75, 0.0), rivals_wait=600)
    scene["creatures"][0]["goals"] = [{"position": [0.0, 0.0]}]
    path = tmp_path / "won_soon.json"
    path.write_text(json.dumps(scene))
    return path


def test_run_stops_at_the_win_and_reports_the_game(tmp_path: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    scene = won_soon(tmp_path)
    assert main(["run", str(scene), "--frames", "1200", "--json", "--quiet"]) == 0
    report = json.loads(capsys.readouterr().out)
    game = report["game"]
    assert (game["mode"], game["outcome"], game["winner"], game["runner"]) == (
        "race", "won", "you", "you"
    )  # fmt: skip
    assert report["frames"] < 1200
    assert game["seconds"] == pytest.approx(report["frames"] / 60, abs=1e-3)
    assert main(["run", str(scene), "--frames", "1200", "--quiet"]) == 0
    line = capsys.readouterr().out
    assert f"game won in {game['seconds']:.1f} s (test race), stopped at frame" in line


def test_play_headless_stops_at_the_win_and_reports_the_game(tmp_path: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    scene = won_soon(tmp_path)
    argv = ["play", str(scene), "--headless", "--frames", "1200", "--json", "--quiet"]
    assert main([*argv, "--threads", "1", "--width", "160", "--height", "120"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["game"]["outcome"] == "won" and report["frames"] < 1200
    assert report["game"]["seconds"] == pytest.approx(report["frames"] / 60, abs=1e-3)


def test_a_scene_without_a_game_runs_every_frame_and_reports_none(capsys) -> None:  # type: ignore[no-untyped-def]
    assert main(["run", "octopus", "--frames", "6", "--json", "--quiet"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["frames"] == 6 and "game" not in report
