"""Wins written off the frame: another process holding the best-times lock never makes
the caller wait, the win lands once the lock is free, and exit does not hang on it."""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

from ecs_tentacles.herding import best_times, win_recorder
from tests.herding.lock_holder import lock_held

FRAME = 1 / 60  # seconds


pytestmark = pytest.mark.usefixtures("data_folder")  # best times kept in the test's folder


def test_a_win_returns_at_once_and_lands_when_the_lock_is_free(data_folder: Path) -> None:
    best_times.record_win("field", 20.0)
    win_recorder.start()  # as the sandbox's Game section does when it is made
    with lock_held(data_folder) as holder:
        started = time.perf_counter()
        pending = win_recorder.record_later("field", 12.5)
        took = time.perf_counter() - started
        assert took < FRAME / 2, f"{1000 * took:.1f} ms"
        time.sleep(0.3)  # the writer has tried the lock by now; it cannot have it
        assert not pending.done and best_times.best_time("field") == 20.0
        holder.release()
        assert pending.wait(10)
    assert (pending.best, pending.new, pending.message) == (12.5, True, "")
    assert best_times.best_time("field") == 12.5


def test_a_lock_never_let_go_is_said_not_waited_on(data_folder: Path) -> None:
    with lock_held(data_folder):
        pending = win_recorder.record_later("field", 12.5, timeout=0.2)
        assert pending.wait(10)
    assert pending.best is None and "best_times.json.lock was held" in pending.message
    assert best_times.best_time("field") is None


def test_a_set_aside_file_is_told_with_the_win(data_folder: Path) -> None:
    data_folder.mkdir()
    (data_folder / "best_times.json").write_text('{"best_seconds": {"a": true, "b": 3}}')
    pending = win_recorder.record_later("c", 4.0)
    assert pending.wait(10)
    assert "'a': true is not a time" in pending.message
    assert "best_times.json.bad.1" in pending.message
    assert best_times.best_times() == {"b": 3.0, "c": 4.0}


def test_no_time_is_refused_at_once() -> None:
    with pytest.raises(ValueError, match="seconds"):
        win_recorder.record_later("c", float("nan"))


EXIT = """
import sys
from ecs_tentacles.herding import win_recorder
win_recorder.record_later("field", 12.5)
"""


def test_a_game_closed_while_the_lock_is_held_exits_saying_so(data_folder: Path) -> None:
    with lock_held(data_folder):
        started = time.perf_counter()
        done = subprocess.run(
            [sys.executable, "-P", "-c", EXIT],
            capture_output=True,
            text=True,
            timeout=60,
            env={**os.environ, "ECS_TENTACLES_DATA": str(data_folder)},
        )
        took = time.perf_counter() - started
    assert done.returncode == 0, done.stderr
    assert "field: best time 12.500 s not saved" in done.stderr
    assert took < best_times.LOCK_WAIT / 2  # the grace, not the lock's whole wait
    assert best_times.best_time("field") is None
