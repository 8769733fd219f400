"""A take written as the bake goes: stopped or killed once chunks are on disk, it leaves
neither a take nor chunks; finished, it is one file."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from ecs_tentacles.take.writer import TakeWriter


def _written_so_far(process: subprocess.Popen[str], folder: Path) -> int:
    """Bytes of the take `process` is writing in `folder` (a file with no name yet)."""
    for fd in Path(f"/proc/{process.pid}/fd").iterdir():
        try:
            target = os.readlink(fd)
        except OSError:
            continue
        if target.startswith(f"{folder}/") and target.endswith("(deleted)"):
            return os.stat(fd).st_size
    return 0


@pytest.mark.parametrize("stop", [signal.SIGINT, signal.SIGKILL])
def test_a_bake_stopped_with_chunks_on_disk_leaves_nothing(
    tmp_path: Path, stop: signal.Signals
) -> None:
    out = tmp_path / "take.npz"
    process = subprocess.Popen(
        [sys.executable, "-P", "-m", "ecs_tentacles", "bake", "octopus", "--seconds", "600",
         "--out", str(out)],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    try:
        deadline = time.monotonic() + 120
        while _written_so_far(process, tmp_path) < 100_000:  # a few chunks stored
            assert process.poll() is None, process.communicate()[1]
            assert time.monotonic() < deadline, "no chunk was written"
            time.sleep(0.05)
        process.send_signal(stop)
        _, err = process.communicate(timeout=60)
    finally:
        process.kill()
    if stop == signal.SIGINT:
        assert process.returncode == 130
        assert err.strip().splitlines()[-1] == (
            "error: interrupted (Ctrl-C); partial outputs removed"
        )
    assert list(tmp_path.iterdir()) == []


def test_an_unfinished_writer_keeps_nothing_and_says_so(tmp_path: Path) -> None:
    out = tmp_path / "take.npz"
    with pytest.raises(RuntimeError, match="not finished"):
        with TakeWriter(out, chunk_frames=2) as writer:
            writer.add_frames({"pos": np.zeros((5, 1, 3), np.float32)})
    assert list(tmp_path.iterdir()) == []
    with TakeWriter(out, chunk_frames=2) as writer:
        writer.add_frames({"pos": np.zeros((5, 1, 3), np.float32)})
        writer.discard()
    assert list(tmp_path.iterdir()) == []
