"""`ecs-tentacles bench`: one JSON object with every key, a human summary, one-line errors."""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import pytest

from ecs_tentacles.cli import main
from tests.cli.conftest import refused
from tests.cli.test_measure import KEYS, lod_crowd


def test_json_has_every_key_finite(capsys: pytest.CaptureFixture[str]) -> None:
    argv = ["bench", "--crowd", "2", "--frames", "4", "--block", "2", "--warmup", "2"]
    assert main([*argv, "--threads", "2", "--idle", "0.5", "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert list(result) == KEYS
    assert all(math.isfinite(v) for k, v in result.items() if k not in ("systems", "tiers"))
    assert all(math.isfinite(v) for v in result["systems"].values())
    assert (result["creatures"], result["threads"], result["frames"]) == (2, 2, 4)


def test_human_summary_of_a_scene_file(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["bench", "three_goals", "--frames", "2", "--warmup", "1", "--threads", "1"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert len(lines) == 4
    assert re.fullmatch(
        r".*three_goals\.json: 1 creature, 61 bodies, 1 shared model \(0"
        r" asleep at the end\), 1 thread;"
        r" built in \d+\.\d\d s",
        lines[0],
    )
    assert "2 frames: " in lines[1] and "bare MuJoCo" in lines[1] and "overhead" in lines[1]
    tiers = "full 1  reduced 0  kinematic 0 (level of detail on: 0 promotions, 0 demotions)"
    assert lines[2] == f"  tiers at the end: {tiers}"
    assert lines[3].startswith("  systems (ms/frame): ")


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--crowd", "2", "--threads", "0"], "argument --threads: must be >= 1, got 0"),
        (["--crowd", "0"], "argument --crowd: must be >= 1, got 0"),
        (["--crowd", "16385"], "argument --crowd: must be <= 16384 (the most creatures a scene"),
        (["octopus", "--crowd", "2"], "argument --crowd: not allowed with argument SCENE"),
        ([], "one of the arguments SCENE --crowd is required"),
        (["--crowd", "2", "--lod", "maybe"], "argument --lod: invalid choice: 'maybe'"),
        (["--crowd", "2", "--focus", "1,2"], "argument --focus: must be X,Y,R (three numbers"),
        (["--crowd", "2", "--focus=1,2,-3"], "argument --focus: radius must be in [0, 100000] m"),
        (["--crowd", "2", "--focus", "a,b,c"], "argument --focus: must be X,Y,R"),
    ],
)
def test_bad_arguments_are_one_line_exit_2(
    argv: list[str], message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    err = refused(["bench", *argv], capsys)
    assert err.startswith("error: ") and message in err and err.count("\n") == 1


def test_bad_scene_is_one_line_exit_2(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    scene = tmp_path / "bad.json"
    scene.write_text('{"version": 1, "creatures": [{"tentacles": {"count": 0}}]}')
    assert main(["bench", str(scene), "--frames", "2"]) == 2
    captured = capsys.readouterr()
    assert (
        captured.err == f"error: {scene}: creatures[0].tentacles.count: must be in [1, 16], got 0\n"
    )
    assert captured.out == ""
    assert main(["bench", "--crowd", "3", "--spacing", "0.2"]) == 2
    assert capsys.readouterr().err.count("\n") == 1


def test_lod_off_and_a_focus_from_the_command_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scene = tmp_path / "crowd.json"
    scene.write_text(json.dumps(lod_crowd()))
    argv = ["bench", str(scene), "--frames", "2", "--block", "2", "--warmup", "1", "--json"]
    assert main([*argv, "--lod", "off"]) == 0
    off = json.loads(capsys.readouterr().out)
    assert (off["lod"], off["tiers"]["full"], off["demotions"]) == (False, 6, 0)
    assert main([*argv, "--focus=-100,-100,1"]) == 0  # a focus far away: the budgets rule
    on = json.loads(capsys.readouterr().out)
    assert on["lod"] is True and on["tiers"] == {"full": 1, "reduced": 2, "kinematic": 3}
    assert main([*argv, "--focus=0,0,1000"]) == 0  # everyone inside the focus
    assert json.loads(capsys.readouterr().out)["tiers"]["full"] == 6
