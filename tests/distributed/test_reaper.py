"""The watchdog of a bake's local Ray finds that Ray's processes by its session, also
those that retitled themselves (`ray::...`) and were re-parented."""

from __future__ import annotations

import subprocess
import sys
import time
from pathlib import Path

import pytest

from ecs_tentacles.distributed.reaper import of_session, reap

psutil = pytest.importorskip("psutil")

HOLDS_A_LOG = """
import sys, time
log = open(sys.argv[1], "w")
print("ready", flush=True)
time.sleep(120)
"""


def test_a_session_s_processes_are_found_by_command_line_or_open_log_and_reaped(
    tmp_path: Path,
) -> None:
    logs = tmp_path / "session_2026-01-01_00-00-00_000001_4242" / "logs"
    logs.mkdir(parents=True)
    named = subprocess.Popen(  # names the session on its command line (GCS, raylet)
        [sys.executable, "-c", "import time; time.sleep(120)", str(logs)]
    )
    retitled = subprocess.Popen(  # only its open log names it (agents, workers)
        [sys.executable, "-c", HOLDS_A_LOG, str(logs / "worker.out")],
        stdout=subprocess.PIPE,
        text=True,
    )
    other = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(120)"])
    try:
        assert retitled.stdout is not None and retitled.stdout.readline() == "ready\n"
        deadline = time.monotonic() + 60.0
        found = {pid for pid, _ in of_session(logs.parent.name)}
        while {named.pid, retitled.pid} - found and time.monotonic() < deadline:
            time.sleep(0.2)  # a loaded machine may not have exec'd the first one yet
            found = {pid for pid, _ in of_session(logs.parent.name)}
        assert found == {named.pid, retitled.pid}
        reap(of_session(logs.parent.name))
        assert named.wait(timeout=30) is not None and retitled.wait(timeout=30) is not None
        assert other.poll() is None
    finally:
        for process in (named, retitled, other):
            process.kill()
            process.wait()
