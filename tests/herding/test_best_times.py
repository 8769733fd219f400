"""The best-times file: in the user's data folder, whole after two games finish at once,
a broken one set aside."""

from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path

import pytest

from ecs_tentacles.herding import best_times


@pytest.fixture(autouse=True)
def data_folder(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    folder = tmp_path / "data"
    monkeypatch.setenv("ECS_TENTACLES_DATA", str(folder))
    return folder


def test_a_win_is_kept_when_it_beats_the_best(data_folder: Path) -> None:
    assert best_times.best_time("1. Open field") is None
    assert best_times.record_win("1. Open field", 44.5) == (44.5, True)
    assert best_times.record_win("1. Open field", 50.0) == (44.5, False)
    assert best_times.record_win("1. Open field", 40.25) == (40.25, True)
    saved = json.loads((data_folder / "best_times.json").read_text())
    assert saved == {"version": 1, "best_seconds": {"1. Open field": 40.25}}
    assert not [p for p in data_folder.iterdir() if "partial" in p.name]


def test_the_default_folder_is_the_users_not_the_packages(monkeypatch: pytest.MonkeyPatch) -> None:
    import ecs_tentacles

    monkeypatch.delenv("ECS_TENTACLES_DATA")
    folder = best_times.data_folder()
    package = Path(ecs_tentacles.__file__).resolve().parent
    assert package not in folder.resolve().parents and folder.name == "ecs_tentacles"


FINISH = """
import os, sys, time
from pathlib import Path
from ecs_tentacles.herding import best_times
go, level = Path(sys.argv[1]), sys.argv[2]
while not go.exists():  # start together
    time.sleep(0.001)
for i in range(40):
    best_times.record_win(level, 60.0 - 0.5 * (i if level != "own" else 39 - i))
"""


def test_two_game_processes_finishing_at_once_leave_one_valid_file(
    data_folder: Path, tmp_path: Path
) -> None:
    go = tmp_path / "go"
    players = [
        subprocess.Popen([sys.executable, "-c", FINISH, str(go), level])
        for level in ("shared", "shared", "own")
    ]
    time.sleep(1.0)  # each imported and waiting
    go.touch()
    for player in players:
        assert player.wait(60) == 0
    saved = json.loads((data_folder / "best_times.json").read_text())
    assert saved["best_seconds"] == {"shared": 40.5, "own": 40.5}
    assert not [p for p in data_folder.iterdir() if "partial" in p.name]


def test_a_broken_file_is_set_aside_with_a_warning(data_folder: Path) -> None:
    data_folder.mkdir()
    (data_folder / "best_times.json").write_text('{"best_seconds": {"x": ')  # cut short
    assert best_times.best_time("x") is None  # reading it says nothing and moves nothing
    assert not (data_folder / "best_times.json.bad").exists()
    with pytest.warns(UserWarning, match="not JSON.*best_times.json.bad"):
        assert best_times.record_win("x", 12.0) == (12.0, True)
    assert (data_folder / "best_times.json.bad").read_text().startswith('{"best_seconds"')
    assert best_times.best_times() == {"x": 12.0}


def test_a_time_that_is_not_a_time_is_refused() -> None:
    with pytest.raises(ValueError, match="seconds"):
        best_times.record_win("x", float("inf"))
