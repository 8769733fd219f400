"""Recording a win off the frame: the best-times file is written on a thread of its own.

    pending = record_later("Open field", 41.3)   # returns at once
    pending.done                  # False while another game holds the file's lock
    pending.best, pending.new     # once done: the level's best now (None: not saved),
                                  # and whether it is this win
    pending.message               # "" or one line for the player (a file set aside,
                                  # or why the time was not saved)

Reads and writes the best-times file (`best_times.record`) on one daemon thread, which
takes wins from a queue in turn and waits up to `best_times.LOCK_WAIT` seconds for the
lock: another game writing, or a stuck program holding it, never holds up a frame, which
only puts the win on the queue and then looks at `done`. `start()` starts the thread
ahead of the first win (the sandbox's Game section does, when it is made): starting a
thread waits for it to run, which on a busy machine can take milliseconds. At exit, wins
still being written get up to `EXIT_GRACE` seconds; one still unwritten then is said on
stderr (one line naming the level).
"""

from __future__ import annotations

import atexit
import queue
import sys
import threading
import time
from pathlib import Path

from filelock import Timeout

from ecs_tentacles.herding import best_times

EXIT_GRACE = 2.0  # seconds the interpreter waits at exit for wins still being written

_writing: set[PendingWin] = set()  # wins not written yet
_queue: queue.SimpleQueue[tuple[PendingWin, float]] = queue.SimpleQueue()
_writer: threading.Thread | None = None
_starting = threading.Lock()


def start() -> None:
    """Start the writing thread now, if it is not running (`record_later` does too)."""
    global _writer
    with _starting:
        if _writer is None or not _writer.is_alive():
            _writer = threading.Thread(target=_write_wins, name="best times", daemon=True)
            _writer.start()


def _write_wins() -> None:
    while True:
        pending, timeout = _queue.get()
        pending._write(timeout)


class PendingWin:
    """One win being written to the best-times file (module docstring)."""

    def __init__(self, level: str, seconds: float, file: Path, timeout: float):
        self.level, self.seconds, self.file = level, seconds, file
        self.best: float | None = None
        self.new = False
        self.message = ""
        self._finished = threading.Event()
        _writing.add(self)
        start()
        _queue.put((self, timeout))

    @property
    def done(self) -> bool:
        return self._finished.is_set()

    def wait(self, timeout: float | None = None) -> bool:
        """Wait at most `timeout` seconds for the write; True once it is done."""
        return self._finished.wait(timeout)

    def _write(self, timeout: float) -> None:
        try:
            recorded = best_times.record(self.level, self.seconds, timeout=timeout, file=self.file)
        except Timeout:
            self.message = (
                f"best time not saved: {self.file.name}.lock was held by another program"
                f" for {timeout:g} s"
            )
        except OSError as error:  # a read-only data folder: the game goes on
            self.message = f"best time not saved: {' '.join(str(error).split())}"
        else:
            self.best, self.new, self.message = recorded.best, recorded.new, recorded.note or ""
        finally:
            _writing.discard(self)
            self._finished.set()


def record_later(
    level: str, seconds: float, *, timeout: float = best_times.LOCK_WAIT
) -> PendingWin:
    """Start writing a win of `level` in `seconds` (ValueError at once if `seconds` is no
    time); returns without waiting for the file or its lock."""
    seconds = best_times.check_seconds(seconds)
    return PendingWin(level, seconds, best_times.path(), timeout)


@atexit.register
def _finish_writing() -> None:
    deadline = time.monotonic() + EXIT_GRACE
    for pending in list(_writing):
        if not pending.wait(max(0.0, deadline - time.monotonic())):
            print(
                f"{pending.level}: best time {pending.seconds:.3f} s not saved:"
                f" {pending.file}.lock is held by another program",
                file=sys.stderr,
            )
