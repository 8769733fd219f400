"""A watchdog that ends the local Ray a bake started if the bake itself is killed.

`ray.init` starts a head node (GCS, raylet, agents, workers) as this process's
descendants. A bake killed with SIGKILL cannot shut them down, and some of them
outlived it by minutes (80 MB each). `Reaper.start()` records those processes and
starts a small watchdog in a session of its own, connected by a pipe. Every second
the watchdog notes the bake's descendants (Ray starts agents and workers later). When
the bake ends normally it closes the pipe first (`Reaper.stop`: the watchdog leaves);
when the bake dies, the kernel closes the pipe, the watchdog sees its parent gone and
ends every process it noted (unless its pid was reused) and whatever they started,
and every process of the bake's Ray session (`session`: named on its command line or in
its open files): one started in the last second (a worker, an agent) was not noted yet,
and the raylet that started it may already be gone.

    python -m ecs_tentacles.distributed.reaper PARENT_PID '[[pid, create_time], ...]' [SESSION]
"""

from __future__ import annotations

import ctypes
import json
import os
import select
import subprocess
import sys
import time
from collections.abc import Iterable

import psutil

from ecs_tentacles.processes import python_module

GRACE_SECONDS = 2.0  # SIGTERM first; SIGKILL whatever still runs after this
WATCH_SECONDS = 1.0  # how often the watchdog notes what the bake's Ray has started
_PR_SET_CHILD_SUBREAPER = 36  # prctl's option number (linux/prctl.h)


class Reaper:
    """The watchdog of this process's Ray (see the module doc)."""

    def __init__(self, process: subprocess.Popen[bytes] | None):
        self.process = process

    @classmethod
    def start(cls, session: str | None = None) -> Reaper:
        """Record this process's descendants (Ray's, just started) and watch over them and
        the processes of Ray session `session` (`get_session_name()`)."""
        me = psutil.Process()
        recorded = []
        for child in me.children(recursive=True):
            try:
                recorded.append([child.pid, child.create_time()])
            except psutil.Error:
                continue
        if not recorded:
            return cls(None)
        process = subprocess.Popen(
            python_module(
                __name__, str(os.getpid()), json.dumps(recorded), *([session] if session else [])
            ),
            stdin=subprocess.PIPE,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            start_new_session=True,  # Ctrl-C or a killed process group must not reach it
        )
        return cls(process)

    def stop(self) -> None:
        """The bake is done and Ray shut down: let the watchdog go."""
        if self.process is None or self.process.stdin is None:
            return
        self.process.stdin.close()
        try:
            self.process.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.process.kill()


def _alive(pid: int) -> bool:
    try:
        return bool(psutil.Process(pid).status() != psutil.STATUS_ZOMBIE)  # (psutil: untyped)
    except psutil.Error:
        return False


def reap(recorded: Iterable[tuple[int, float]]) -> None:
    """Terminate the recorded processes (if they are still the same ones) and their
    descendants; kill what is left after `GRACE_SECONDS`."""
    victims: list[psutil.Process] = []
    for pid, created in recorded:
        try:
            process = psutil.Process(int(pid))
            if abs(process.create_time() - float(created)) > 0.01:
                continue  # the pid was reused
            victims += [process, *process.children(recursive=True)]
        except psutil.Error:
            continue
    for process in victims:
        try:
            process.terminate()
        except psutil.Error:
            pass
    _, alive = psutil.wait_procs(victims, timeout=GRACE_SECONDS)
    for process in alive:
        try:
            process.kill()
        except psutil.Error:
            pass


def adopt_orphans(on: bool) -> bool:
    """Linux: make this process the reaper of its orphaned descendants (or stop), so
    that a process whose parent dies stays a descendant of this one
    (`PR_SET_CHILD_SUBREAPER`): a raylet ended while it started its agents leaves them
    to us, not to init, and `end_started_since` still finds them. False elsewhere."""
    if not sys.platform.startswith("linux"):
        return False
    try:
        prctl = ctypes.CDLL(None, use_errno=True).prctl
    except (OSError, AttributeError):
        return False
    return bool(prctl(_PR_SET_CHILD_SUBREAPER, int(on), 0, 0, 0) == 0)


def descendants() -> set[tuple[int, float]]:
    """(pid, start time) of every descendant of this process."""
    return {(int(pid), float(created)) for pid, created in _descendants(os.getpid())}


def end_started_since(before: set[tuple[int, float]], rounds: int = 5) -> None:
    """End every descendant of this process not in `before` (a Ray start cut short) and
    theirs, as `reap` does; again while new ones appear (a raylet was starting agents)."""
    for _ in range(rounds):
        new = descendants() - before
        if not new:
            return
        reap(new)


def _descendants(pid: int) -> list[tuple[int, float]]:
    try:
        return [(p.pid, p.create_time()) for p in psutil.Process(pid).children(recursive=True)]
    except psutil.Error:
        return []


def of_session(session: str) -> list[tuple[int, float]]:
    """(pid, create_time) of every living process of Ray session `session`: its command
    line names it (GCS, raylet), or a file it has open does (agents and workers retitle
    themselves `ray::...`, but keep their logs in the session's folder open)."""
    found: list[tuple[int, float]] = []
    for process in psutil.process_iter(["cmdline", "create_time", "status"]):
        if process.info["status"] == psutil.STATUS_ZOMBIE:
            continue
        named = any(session in part for part in process.info["cmdline"] or ())
        try:
            named = named or any(session in f.path for f in process.open_files())
        except psutil.Error:  # gone, or another user's
            continue
        if named:
            found.append((process.pid, process.info["create_time"]))
    return found


def main(argv: list[str]) -> int:
    parent, recorded = int(argv[0]), json.loads(argv[1])
    session = argv[2] if len(argv) > 2 else None
    known = {int(pid): created for pid, created in recorded}
    while True:  # until the bake closes the pipe, or dies and the kernel does
        ready, _, _ = select.select([sys.stdin.buffer], [], [], WATCH_SECONDS)
        if ready and not os.read(sys.stdin.fileno(), 4096):
            break
        # Ray starts agents and workers later, under its raylet: keep them on the list,
        # for the raylet may be gone (and they re-parented) by the time the bake dies
        known.update({pid: created for pid, created in _descendants(parent) if pid != os.getpid()})
    deadline = time.monotonic() + 1.0
    while _alive(parent) and time.monotonic() < deadline:
        time.sleep(0.05)  # a bake that closed the pipe itself is about to exit
    if _alive(parent):
        return 0  # a normal end: the bake shut Ray down itself
    if session:  # what started since the last look, wherever it was re-parented
        known.update({pid: created for pid, created in of_session(session) if pid != os.getpid()})
    reap(known.items())
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
