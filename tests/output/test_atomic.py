"""Atomic output: the target is whole or untouched, even when the writer is killed."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from ecs_tentacles.output.atomic import (
    STALE_SECONDS,
    OutputConflict,
    OutputError,
    atomic_file,
    atomic_output,
    claim,
)


def test_success_replaces_the_target_and_leaves_nothing_else(tmp_path: Path) -> None:
    target = tmp_path / "out.usda"
    target.write_text("old")
    with atomic_output(target) as temporary:
        assert temporary.parent == tmp_path and temporary.suffix == ".usda"
        assert temporary.name.startswith(".out.") and temporary.exists()
        temporary.write_text("new")
        assert target.read_text() == "old"  # not visible before the end
    assert target.read_text() == "new"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.usda"]


@pytest.mark.parametrize("error", [RuntimeError("disk on fire"), KeyboardInterrupt()])
def test_an_error_while_writing_keeps_the_old_file(tmp_path: Path, error: BaseException) -> None:
    target = tmp_path / "out.npz"
    target.write_bytes(b"previous take")
    with pytest.raises(type(error)):
        with atomic_output(target) as temporary:
            temporary.write_bytes(b"half a ")
            raise error
    assert target.read_bytes() == b"previous take"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.npz"]


KILLED_WRITER = """
import sys, time
from ecs_tentacles.output.atomic import atomic_output
with atomic_output(sys.argv[1]) as temporary:
    with open(temporary, "wb") as handle:
        handle.write(b"half a file")
        handle.flush()
        print("writing", flush=True)
        time.sleep(60)
"""


@pytest.mark.parametrize("previous", [None, b"the previous file"])
def test_a_writer_killed_mid_write_never_leaves_a_partial_target(
    tmp_path: Path, previous: bytes | None
) -> None:
    target = tmp_path / "out.glb"
    if previous is not None:
        target.write_bytes(previous)
    writer = subprocess.Popen(
        [sys.executable, "-c", KILLED_WRITER, str(target)], stdout=subprocess.PIPE, text=True
    )
    assert writer.stdout is not None and writer.stdout.readline() == "writing\n"
    writer.send_signal(signal.SIGKILL)
    assert writer.wait(timeout=30) == -signal.SIGKILL
    if previous is None:
        assert not target.exists()
    else:
        assert target.read_bytes() == previous
    # what a kill can leave is the hidden temporary file, never the target
    assert next(p.name for p in tmp_path.iterdir() if p != target).startswith(".out.")


# -- one writer for every output: exclusive names, races, signals, stale leftovers ----------


def test_a_later_run_removes_stale_leftovers_of_this_tool_and_says_so(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    target = tmp_path / "take.usda"
    day_old = time.time() - STALE_SECONDS - 60
    stale = [
        ".take.0123abcd.partial.usda",  # ours
        ".take.0123abcd.partial.X6bhx5",  # USD's own temporary file, next to ours
        ".take.partial.usda",  # the old fixed name
    ]
    kept = [".take.89abcdef.partial.usda", ".other.0123abcd.partial.usda", "take.0123.usda"]
    for name in stale + kept:
        (tmp_path / name).write_text("x")
        os.utime(tmp_path / name, (day_old, day_old))
    os.utime(tmp_path / kept[0])  # fresh: perhaps a run still writing
    with atomic_output(target) as temporary:
        temporary.write_text("#usda 1.0\n")
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([*kept, "take.usda"])
    lines = capsys.readouterr().err.splitlines()
    assert len(lines) == 3 and all("partial file left by an interrupted run" in x for x in lines)
    assert {line.split("removed ")[1].split(",")[0] for line in lines} == set(stale)


def test_a_planted_symlink_at_a_temporary_name_is_never_followed(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    victim = tmp_path / "victim.txt"
    victim.write_text("precious")
    tokens = iter(["deadbeef", "deadbeef", "0badf00d"])
    monkeypatch.setattr("ecs_tentacles.output.atomic.secrets.token_hex", lambda n: next(tokens))
    for name in (".out.deadbeef.partial.png", ".out.partial.png"):
        (tmp_path / name).symlink_to(victim)
    with atomic_file(tmp_path / "out.png") as handle:
        handle.write(b"picture")
    assert victim.read_text() == "precious"
    assert (tmp_path / "out.png").read_bytes() == b"picture"
    assert not (tmp_path / "out.png").is_symlink()
    assert all((tmp_path / n).is_symlink() for n in (".out.deadbeef.partial.png",))


def test_two_writers_to_one_path_exactly_one_wins(tmp_path: Path) -> None:
    target = tmp_path / "take.npz"
    with pytest.raises(OutputConflict) as caught:
        with atomic_output(target) as first:
            with atomic_output(target) as second:
                second.write_bytes(b"second")
            first.write_bytes(b"first")
    assert target.read_bytes() == b"second"  # the one that finished first
    assert str(caught.value).startswith(f"{target}: another program wrote this file")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["take.npz"]


def test_a_claimed_target_written_by_another_before_the_write_starts_is_kept(
    tmp_path: Path,
) -> None:
    target = tmp_path / "take.npz"
    claim(target)  # a run starts: the file is absent
    target.write_bytes(b"theirs")  # another program finishes first
    with pytest.raises(OutputConflict):
        with atomic_output(target) as mine:
            mine.write_bytes(b"mine")
    assert target.read_bytes() == b"theirs"
    with atomic_output(target) as again:  # the claim was used: a later write is a new run
        again.write_bytes(b"mine")
    assert target.read_bytes() == b"mine"


def test_claiming_in_a_missing_folder_is_refused(tmp_path: Path) -> None:
    with pytest.raises(OutputError, match="does not exist"):
        claim(tmp_path / "nowhere" / "take.npz")
