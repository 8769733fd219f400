"""Atomic output: the target is whole or untouched, even when the writer is killed."""

from __future__ import annotations

import signal
import subprocess
import sys
from pathlib import Path

import pytest

from ecs_tentacles.export.atomic import atomic_output


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
from ecs_tentacles.export.atomic import atomic_output
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
