"""Every output kind through the one writer: SIGTERM and SIGKILL mid-write, then clean-up.

One child process starts every writer the project has (take npz, USD usda, glTF glb,
PNG, MP4 through ffmpeg, the creator's scene JSON), nested so that all six temporary
files exist (and ffmpeg runs) at the moment the signal arrives.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from ecs_tentacles.creator import CreatureDesign
from ecs_tentacles.export import write
from ecs_tentacles.output.atomic import STALE_SECONDS, OutputConflict
from ecs_tentacles.render.output import VideoWriter, save_png
from ecs_tentacles.take import Take

TARGETS = ("take.npz", "take.usda", "take.glb", "shot.png", "clip.mp4", "scene.json")
# the writers that take a path make a named temporary file; those that take a file
# write an unnamed one (Linux O_TMPFILE), named only once it is whole
NAMED = ("take.usda", "clip.mp4")

CHILD = """
import os, sys, time
from pathlib import Path
import numpy as np
from ecs_tentacles.cli import Terminated, terminate_by_exception
from ecs_tentacles.creator import CreatureDesign
from ecs_tentacles.export import write
from ecs_tentacles.take import Take
from ecs_tentacles.render.output import VideoWriter, save_png

take, out = Take.load(sys.argv[1]), Path(sys.argv[2])
writers = [
    lambda: write(take, out / "take.npz"),
    lambda: write(take, out / "take.usda"),
    lambda: write(take, out / "take.glb"),
    lambda: save_png(np.zeros((64, 64, 3), np.uint8), out / "shot.png"),
    lambda: CreatureDesign().export(out / "scene.json"),
]
real_fsync = os.fsync

def nest(descriptor):  # a finished temporary file, about to be renamed: start the next
    real_fsync(descriptor)
    if writers:
        writers.pop(0)()
    else:
        print("writing", video._process.pid, flush=True)
        time.sleep(60)

with terminate_by_exception():
    video = VideoWriter(out / "clip.mp4", 64, 64, 30.0)
    try:
        for i in range(3):
            video.add(np.full((64, 64, 3), 40 * i, np.uint8))
        os.fsync = nest
        writers.pop(0)()
    except BaseException:
        video.abort()
        raise
"""


@pytest.fixture
def take_file(tmp_path: Path, guided_take: Take) -> Path:
    path = tmp_path / "source" / "small.npz"
    path.parent.mkdir()
    guided_take.save(path)
    return path


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    stat = Path(f"/proc/{pid}/stat")
    return not (stat.exists() and stat.read_text().split()[2] == "Z")


def _start(take_file: Path, out: Path) -> tuple[subprocess.Popen[str], int]:
    child = subprocess.Popen(
        [sys.executable, "-c", CHILD, str(take_file), str(out)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    assert child.stdout is not None
    line = child.stdout.readline()
    assert line.startswith("writing"), child.communicate()[1]
    partials = sorted(p.name for p in out.iterdir())
    assert len(partials) == len(NAMED) and all(".partial." in name for name in partials)
    unnamed = [os.readlink(f) for f in Path(f"/proc/{child.pid}/fd").iterdir()]
    unnamed = [f for f in unnamed if f.startswith(f"{out}/#") and f.endswith("(deleted)")]
    assert len(unnamed) == len(TARGETS) - len(NAMED)  # open, with no name in the folder
    return child, int(line.split()[1])


def _later_runs(take: Take, out: Path) -> None:
    """What a user runs next: each output written again to the same place."""
    for name in TARGETS:
        _write_one(name, take, out)


def test_sigterm_mid_write_removes_every_partial_and_stops_ffmpeg(
    tmp_path: Path, take_file: Path
) -> None:
    out = tmp_path / "out"
    out.mkdir()
    child, ffmpeg = _start(take_file, out)
    child.send_signal(signal.SIGTERM)
    _, err = child.communicate(timeout=30)
    assert child.returncode == 1 and err.strip().endswith("Terminated: SIGTERM")
    assert list(out.iterdir()) == []
    assert not _alive(ffmpeg)


def test_sigkill_leaves_only_named_partials_that_a_later_run_removes_after_a_day(
    tmp_path: Path, take_file: Path, guided_take: Take, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "out"
    out.mkdir()
    child, ffmpeg = _start(take_file, out)
    child.send_signal(signal.SIGKILL)
    child.communicate(timeout=30)
    for _ in range(100):  # ffmpeg dies with its parent (PR_SET_PDEATHSIG)
        if not _alive(ffmpeg):
            break
        time.sleep(0.05)
    assert not _alive(ffmpeg)
    leftovers = sorted(out.iterdir())  # the unnamed files went with the process
    assert len(leftovers) == len(NAMED) and not any(p.name in TARGETS for p in leftovers)
    _later_runs(guided_take, out)  # less than a day old: perhaps still being written
    assert set(leftovers) < set(out.iterdir()) and not capsys.readouterr().err
    old = time.time() - STALE_SECONDS - 1
    for path in leftovers:
        os.utime(path, (old, old))
    _later_runs(guided_take, out)
    assert sorted(p.name for p in out.iterdir()) == sorted(TARGETS)
    lines = capsys.readouterr().err.splitlines()
    assert len(lines) == len(NAMED)
    assert all("a partial file left by an interrupted run" in line for line in lines)


def test_two_videos_to_one_path_the_first_to_finish_wins(tmp_path: Path) -> None:
    import imageio_ffmpeg

    target = tmp_path / "crawl.mp4"
    first = VideoWriter(target, 64, 64, 30.0)
    second = VideoWriter(target, 64, 64, 30.0)
    for _ in range(3):
        first.add(np.zeros((64, 64, 3), np.uint8))
    for _ in range(5):
        second.add(np.full((64, 64, 3), 200, np.uint8))
    assert first.close() == target
    with pytest.raises(OutputConflict):
        second.close()
    frames, _ = imageio_ffmpeg.count_frames_and_secs(str(target))
    assert frames == 3
    assert [p.name for p in tmp_path.iterdir()] == ["crawl.mp4"]


def _write_one(name: str, take: Take, out: Path) -> None:
    if name == "shot.png":
        save_png(np.zeros((64, 64, 3), np.uint8), out / name)
    elif name == "scene.json":
        CreatureDesign().export(out / name)
    elif name == "clip.mp4":
        video = VideoWriter(out / name, 64, 64, 30.0)
        video.add(np.zeros((64, 64, 3), np.uint8))
        video.close()
    else:
        write(take, out / name)


@pytest.mark.parametrize("name", TARGETS)
def test_symlinks_planted_at_every_temporary_name_are_never_followed(
    name: str, tmp_path: Path, guided_take: Take, monkeypatch: pytest.MonkeyPatch
) -> None:
    victim = tmp_path / "victim.txt"
    victim.write_text("precious")
    out = tmp_path / "out"
    out.mkdir()
    stem, suffix = name.split(".")
    planted = [f".{stem}.deadbeef.partial.{suffix}", f".{stem}.partial.{suffix}"]
    for link in planted:
        (out / link).symlink_to(victim)
    tokens = iter(["deadbeef", "deadbeef", "0badf00d"])
    monkeypatch.setattr("ecs_tentacles.output.atomic.secrets.token_hex", lambda n: next(tokens))
    _write_one(name, guided_take, out)
    assert victim.read_text() == "precious"
    assert (out / name).is_file() and not (out / name).is_symlink()
    assert sorted(p.name for p in out.iterdir()) == sorted([*planted, name])
    assert all((out / link).is_symlink() for link in planted)


def test_a_temporary_file_swapped_for_a_symlink_mid_video_is_not_followed(
    tmp_path: Path,
) -> None:
    from ecs_tentacles.output.atomic import OutputError

    victim = tmp_path / "victim.txt"
    victim.write_text("precious")
    video = VideoWriter(tmp_path / "clip.mp4", 64, 64, 30.0)
    video.partial.unlink()
    video.partial.symlink_to(victim)  # someone who can write the folder, mid-recording
    for _ in range(3):
        video.add(np.zeros((64, 64, 3), np.uint8))
    with pytest.raises(OutputError, match="was removed or replaced while writing"):
        video.close()
    assert victim.read_text() == "precious"
    assert not (tmp_path / "clip.mp4").exists()
