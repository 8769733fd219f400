"""`ecs-tentacles play`: headless output and argument errors."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
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
    out = capsys.readouterr().out
    assert out.startswith(f"{scene}: 3 frames (0.05 s simulated, physics ")
    assert out.endswith(f" real time); wrote {shot}\n")
    with Image.open(shot) as image:
        assert image.size == (320, 180)
    assert main([*argv, "--screenshot", str(shot), *size, "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert (result["frames"], result["screenshot"]) == (3, str(shot))
    assert result["physics_ms"] > 0  # the median frame's physics, and what it means
    assert result["realtime_factor"] == pytest.approx(1000 / 60 / result["physics_ms"], rel=1e-2)


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


def test_headless_play_with_nothing_to_keep_is_refused(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["play", "octopus", "--headless", "--frames", "2", "--quiet"]) == 2
    assert capsys.readouterr().err == (
        "error: play: --headless keeps nothing without --screenshot FILE.png,"
        " --video FILE.mp4 or --json\n"
    )


def _last_frame(video: Path) -> np.ndarray:
    """The last frame of an MP4 as (height, width, 3) uint8 (decoded by imageio-ffmpeg)."""
    import imageio_ffmpeg

    frames = imageio_ffmpeg.read_frames(str(video))
    meta = next(frames)
    width, height = meta["size"]
    *_, last = frames
    return np.frombuffer(last, np.uint8).reshape(height, width, 3)


def test_a_headless_video_has_no_hud_unless_asked(tmp_path: Path) -> None:
    argv = ["play", "octopus", "--headless", "--frames", "3", "--quiet"]
    size = ["--width", "640", "--height", "360"]
    bare, shown = tmp_path / "bare.mp4", tmp_path / "hud.mp4"
    assert main([*argv, *size, "--video", str(bare)]) == 0
    assert main([*argv, *size, "--video", str(shown), "--hud"]) == 0
    left = (slice(None), slice(0, 200))  # where the HUD's panel sits
    a, b = _last_frame(bare).astype(int), _last_frame(shown).astype(int)
    right = (slice(None), slice(-120, None))
    panel, elsewhere = np.abs(a[left] - b[left]).mean(), np.abs(a[right] - b[right]).mean()
    assert panel > 10 and panel > 3 * elsewhere  # the panel covers the view only there


@pytest.mark.parametrize(
    ("camera", "message"),
    [
        (["--camera", "sideways"], "error: argument --camera: must be frame-all, follow NAME or"),
        (["--camera", "1,2,3"], "error: argument --camera: must be frame-all, follow NAME or"),
        (["--camera", "-1,-1,-1,-1,-1,-1"], "error: argument --camera: the eye and the point"),
        (["--camera", "follow", "nobody"], "error: argument --camera: no creature named 'nobody'"),
    ],
)
def test_a_bad_camera_is_one_line_and_exit_2(
    tmp_path: Path, camera: list[str], message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    argv = ["play", "octopus", "--headless", "--frames", "1", "--quiet", *camera]
    try:
        code = main([*argv, "--width", "128", "--height", "72", "--json"])
    except SystemExit as exit_:
        code = int(exit_.code or 0)
    err = capsys.readouterr().err
    assert code == 2
    assert message in err and len(err.strip().splitlines()) == 1


@pytest.mark.parametrize("camera", ["frame-all", "follow octopus", "-3,-4,2,0,0,0"])
def test_play_takes_a_camera(tmp_path: Path, camera: str) -> None:
    shot = tmp_path / "shot.png"
    argv = ["play", "octopus", "--headless", "--frames", "2", "--quiet", "--no-hud"]
    assert main([*argv, "--camera", *camera.split(" ", 1), "--screenshot", str(shot)]) == 0
    assert shot.exists()
