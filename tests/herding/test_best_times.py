"""The best-times file: in the user's data folder, whole after two games finish at once,
a broken one set aside."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
import time
from pathlib import Path

import pytest

from ecs_tentacles.herding import best_times

pytestmark = pytest.mark.usefixtures("data_folder")  # best times kept in the test's folder


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
    assert not (data_folder / "best_times.json.bad.1").exists()
    with pytest.warns(UserWarning, match="not JSON.*best_times.json.bad.1"):
        assert best_times.record_win("x", 12.0) == (12.0, True)
    assert (data_folder / "best_times.json.bad.1").read_text().startswith('{"best_seconds"')
    assert best_times.best_times() == {"x": 12.0}


def test_a_time_that_is_not_a_time_is_refused() -> None:
    with pytest.raises(ValueError, match="seconds"):
        best_times.record_win("x", float("inf"))


def _file(folder: Path, text: str | bytes) -> Path:
    folder.mkdir(exist_ok=True)
    file = folder / "best_times.json"
    file.write_bytes(text if isinstance(text, bytes) else text.encode())
    return file


def _asides(folder: Path) -> list[Path]:
    return sorted(p for p in folder.iterdir() if ".bad" in p.name)


HUGE = "9" * 400
DEEP = "[" * 100_000 + "]" * 100_000


@pytest.mark.parametrize(
    ("value", "said"),
    [
        (HUGE, "a 400-digit number"),
        ("-" + HUGE, "a 400-digit number"),
        ("1e400", "inf"),
        ("NaN", "NaN"),
        ("-Infinity", "-Infinity"),
        ("true", "true"),
        ("0", "0"),
        ("-3.5", "-3.5"),
        ('"12.5"', "a string"),
        ("[12.5]", "a list"),
        ("null", "null"),
    ],
)
def test_a_bad_entry_is_left_out_and_the_good_ones_kept(
    data_folder: Path, value: str, said: str
) -> None:
    text = f'{{"version": 1, "best_seconds": {{"good": 12.5, "bad": {value}, "also": 7}}}}'
    file = _file(data_folder, text)
    assert best_times.best_times() == {"good": 12.5, "also": 7.0}  # read: nothing moved
    assert file.read_text() == text and _asides(data_folder) == []
    # the next win keeps the good times and sets the whole old file aside, saying so once
    with pytest.warns(UserWarning, match=f"'bad': {re.escape(said)} is not") as warned:
        assert best_times.record_win("good", 20.0) == (12.5, False)
    assert len(warned) == 1 and "best_times.json.bad.1" in str(warned[0].message)
    assert best_times.best_times() == {"good": 12.5, "also": 7.0}
    assert json.loads(file.read_text())["best_seconds"] == {"good": 12.5, "also": 7.0}
    assert _asides(data_folder) == [data_folder / "best_times.json.bad.1"]
    assert (data_folder / "best_times.json.bad.1").read_text() == text  # nothing lost


@pytest.mark.parametrize(
    ("text", "said"),
    [
        (f'{{"best_seconds": {{"x": 12.5, "deep": {DEEP}}}}}', "nested too deeply"),
        ('{"best_seconds": [12.5]}', "not a best-times file"),
        ('{"best_seconds": {"x": 12.5}}' + " " * (1 << 20), "larger than 1 MiB"),
        (b'{"best_seconds": {"x\xff": 12.5}}', "not UTF-8"),
    ],
)
def test_a_file_that_does_not_read_reads_as_no_times_and_is_set_aside_whole(
    data_folder: Path, text: str | bytes, said: str
) -> None:
    file = _file(data_folder, text)
    assert best_times.best_times() == {}
    with pytest.warns(UserWarning, match=said):
        assert best_times.record_win("x", 30.0) == (30.0, True)
    kept = (data_folder / "best_times.json.bad.1").read_bytes()
    assert kept == (text if isinstance(text, bytes) else text.encode())
    assert json.loads(file.read_text())["best_seconds"] == {"x": 30.0}


def test_a_fifo_in_the_files_place_is_refused_at_once(data_folder: Path) -> None:
    data_folder.mkdir()
    os.mkfifo(data_folder / "best_times.json")  # opening it for reading would block
    assert best_times.best_times() == {}
    with pytest.warns(UserWarning, match="not a regular file"):
        assert best_times.record_win("x", 30.0) == (30.0, True)
    assert best_times.best_times() == {"x": 30.0}


def test_no_set_aside_file_is_ever_overwritten(data_folder: Path) -> None:
    texts = ['{"best_seconds": {"a": true}}', "{cut", '{"best_seconds": {"b": 1e999}}']
    for number, text in enumerate(texts, 1):
        _file(data_folder, text)
        with pytest.warns(UserWarning, match=f"best_times.json.bad.{number}"):
            best_times.record_win("c", 10.0 + number)
    assert [p.read_text() for p in _asides(data_folder)] == texts
    assert best_times.best_times() == {"c": 13.0}  # the last file held no time of c


def test_a_time_is_stored_as_it_is_however_short(data_folder: Path) -> None:
    assert best_times.record_win("quick", 0.0004) == (0.0004, True)
    assert best_times.record_win("quick", 1 / 3) == (0.0004, False)
    assert best_times.record_win("slow", 1 / 3) == (1 / 3, True)
    assert best_times.best_times() == {"quick": 0.0004, "slow": 1 / 3}
    assert not list(data_folder.glob("*.bad*"))


@pytest.mark.parametrize("seconds", [True, 0.0, -1.0, float("nan")])
def test_a_win_in_no_time_is_refused(seconds: float) -> None:
    with pytest.raises(ValueError, match="seconds"):
        best_times.record_win("x", seconds)


@pytest.mark.parametrize(
    "text",
    [f'{{"best_seconds": {{"test level": {HUGE}}}}}', f'{{"best_seconds": {{"deep": {DEEP}}}}}'],
    ids=["huge", "deep"],
)
def test_a_level_opens_whatever_the_best_times_file_holds(tmp_path: Path, text: str) -> None:
    """A real `play` of a herding level, beside a file a careless hand broke."""
    from tests.herding.levels import level

    scene = tmp_path / "level.json"
    scene.write_text(json.dumps(level()))
    data = tmp_path / "data"
    _file(data, text)
    play = ["play", "--headless", "--frames", "2", "--width", "160", "--height", "96", "--json"]
    done = subprocess.run(
        [sys.executable, "-P", "-m", "ecs_tentacles", *play, str(scene)],
        capture_output=True,
        text=True,
        timeout=120,
        cwd=tmp_path,
        env={**os.environ, "ECS_TENTACLES_DATA": str(data)},
    )
    assert done.returncode == 0, done.stderr
    assert (data / "best_times.json").read_text() == text  # reading moves nothing
