"""Atomic output: the target is whole or untouched, even when the writer is killed."""

from __future__ import annotations

import json
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
from ecs_tentacles.take import Take


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


# -- a stop that lands just after the rename -------------------------------------------

AFTER_RENAME = """
import os, signal, sys

from ecs_tentacles.cli import main

real, name, stop = os.replace, sys.argv[1], getattr(signal, sys.argv[2])


def replace(source, target, **options):  # the real rename, then the signal at once
    real(source, target, **options)
    if os.path.basename(target) == name:
        os.kill(os.getpid(), stop)


os.replace = replace
sys.exit(main(sys.argv[3:]))
"""
SCENE = {"version": 1, "creatures": [{"name": "octo", "tentacles": {"count": 3, "links": 2}}]}


def _stopped_after_rename(folder: Path, name: str, stop: str, *argv: str) -> tuple[int, str]:
    """Run the command line on `argv` in `folder`; the process sends itself `stop` just
    after `name` is renamed into place. Exit code and stderr."""
    (folder / "scene.json").write_text(json.dumps(SCENE))
    done = subprocess.run(
        [sys.executable, "-P", "-c", AFTER_RENAME, name, stop, *argv],
        cwd=folder,
        capture_output=True,
        text=True,
        timeout=120,
    )
    return done.returncode, done.stderr


@pytest.mark.parametrize(
    ("stop", "argv", "said"),
    [
        ("SIGTERM", ["bake", "scene.json", "--seconds", "0.1", "--quiet"], "SIGTERM"),
        ("SIGINT", ["migrate", "scene.json"], "Ctrl-C"),
    ],
)
def test_a_stop_just_after_the_last_rename_keeps_the_output_and_exits_0(
    tmp_path: Path, stop: str, argv: list[str], said: str
) -> None:
    """Before: exit 143 (130), "partial outputs removed", and the whole file there."""
    out = tmp_path / ("take.npz" if argv[0] == "bake" else "scene.migrated.json")
    if argv[0] == "bake":
        argv = [*argv, "--out", out.name]
    code, err = _stopped_after_rename(tmp_path, out.name, stop, *argv)
    assert (code, err.splitlines()[-1]) == (
        0,
        f"note: {said} came once every output was written: kept {out}",
    ), err
    if argv[0] == "bake":
        assert Take.load(out).frames == 7  # whole: 0.1 s at 60 fps
    else:
        assert json.loads(out.read_text())["creatures"][0]["name"] == "octo"
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(["scene.json", out.name])


def test_a_stop_after_one_of_two_outputs_keeps_that_one_and_says_so(tmp_path: Path) -> None:
    argv = ["bake", "scene.json", "--seconds", "0.05", "--quiet", "--out", "{name}.npz"]
    argv += ["--wedge", "creatures[0].tentacles.count=3,4"]
    first = tmp_path / "creatures0.tentacles.count-3.npz"  # the second and wedge.json: never
    code, err = _stopped_after_rename(tmp_path, first.name, "SIGTERM", *argv)
    assert (code, err.splitlines()[-1]) == (
        143,
        f"error: stopped by SIGTERM; partial outputs removed; kept {first}, written whole",
    ), err
    assert Take.load(first).frames == 4
    assert sorted(p.name for p in tmp_path.iterdir()) == [first.name, "scene.json"]
