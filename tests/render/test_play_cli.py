"""`ecs-tentacles play`: headless output and argument errors."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from PIL import Image

from ecs_tentacles.cli import main
from ecs_tentacles.scene.load import bundled_scene


def test_headless_play_writes_the_screenshot(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    shot = tmp_path / "shot.png"
    argv = ["play", "three_goals", "--headless", "--frames", "3", "--quiet"]
    size = ["--width", "320", "--height", "180"]
    assert main([*argv, "--screenshot", str(shot), *size]) == 0
    scene = bundled_scene("three_goals")
    assert capsys.readouterr().out == f"{scene}: 3 frames (0.05 s simulated); wrote {shot}\n"
    with Image.open(shot) as image:
        assert image.size == (320, 180)
    assert main([*argv, "--screenshot", str(shot), *size, "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert (result["frames"], result["screenshot"]) == (3, str(shot))


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--screenshot", "x.png"], "error: argument --screenshot/--video: needs --headless"),
        (["--headless", "--width", "333"], "argument --width: must be an even number of pixels"),
        (["--headless", "--width", "0"], "argument --width: must be an even number of pixels"),
        (
            ["--headless", "--video", "clip.avi"],
            "argument --video: must end in .mp4, got 'clip.avi'",
        ),
    ],
)
def test_bad_play_arguments_exit_2(
    argv: list[str], message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    try:
        code = main(["play", "octopus", *argv])
    except SystemExit as exit_:
        code = int(exit_.code or 0)
    assert code == 2
    assert message in capsys.readouterr().err
