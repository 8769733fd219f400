"""`ecs-tentacles` run in a process of its own with stderr on a pseudo-terminal, as from a
shell (100 columns), for the tests of what a user sees drawn there (bars, Ctrl-C)."""

from __future__ import annotations

import fcntl
import os
import pty
import re
import select
import signal
import struct
import subprocess
import sys
import termios
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def on_a_terminal(args: list[str], cwd: Path) -> tuple[subprocess.Popen[bytes], int]:
    """`ecs-tentacles ARGS` started in `cwd`: the process and the terminal's reading end
    (read it with `drawn_until_closed`)."""
    main, child = pty.openpty()
    fcntl.ioctl(child, termios.TIOCSWINSZ, struct.pack("HHHH", 24, 100, 0, 0))  # 100 columns
    process = subprocess.Popen(
        [sys.executable, "-m", "ecs_tentacles", *args],
        cwd=cwd, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=child,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
    )  # fmt: skip
    os.close(child)
    return process, main


def drawn_until_closed(main: int) -> str:
    """Everything still to be read from the terminal `main` until the process closes it;
    `main` is closed after."""
    drawn = bytearray()
    while True:
        try:
            piece = os.read(main, 65536)
        except OSError:  # EIO: the process closed the terminal (it ended)
            break
        if not piece:
            break
        drawn += piece
    os.close(main)
    return drawn.decode(errors="replace")


def interrupted_on_a_terminal(args: list[str], cwd: Path, shown: str) -> tuple[int, str]:
    """`ecs-tentacles ARGS` given Ctrl-C (SIGINT) once the terminal shows a match of the
    pattern `shown` (within 2 minutes): (exit code, everything drawn)."""
    process, main = on_a_terminal(args, cwd)
    drawn, deadline = "", time.monotonic() + 120
    while re.search(shown, drawn) is None:
        assert time.monotonic() < deadline and process.poll() is None, drawn
        if select.select([main], [], [], 0.5)[0]:
            drawn += os.read(main, 65536).decode(errors="replace")
    process.send_signal(signal.SIGINT)
    process.wait(timeout=60)
    return process.returncode, drawn + drawn_until_closed(main)


def export_stopped_leaves_only_the_take(take: Path, out: str, shown: str) -> None:
    """`ecs-tentacles export TAKE --out OUT` in the take's folder, given Ctrl-C once the
    terminal shows `shown`: exit 130, its one line said, and the take alone left in the
    folder (no partial file, ours or a library's)."""
    code, drawn = interrupted_on_a_terminal(["export", str(take), "--out", out], take.parent, shown)
    assert code == 130, drawn
    assert "error: interrupted (Ctrl-C); partial outputs removed" in drawn
    assert [p.name for p in take.parent.iterdir()] == [take.name]
