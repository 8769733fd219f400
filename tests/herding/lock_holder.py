"""Another real process holding the best-times file's lock until told to let go."""

from __future__ import annotations

import subprocess
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

HOLD = """
import sys
from filelock import FileLock
with FileLock(sys.argv[1]):
    print("held", flush=True)
    sys.stdin.readline()
"""


class Holder:
    def __init__(self, lock: Path):
        self.process = subprocess.Popen(
            [sys.executable, "-P", "-c", HOLD, str(lock)],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            text=True,
        )
        assert self.process.stdout is not None and self.process.stdout.readline() == "held\n"

    def release(self) -> None:
        """Let go of the lock (the holder exits)."""
        if self.process.poll() is None:
            assert self.process.stdin is not None
            self.process.stdin.write("\n")
            self.process.stdin.close()
            assert self.process.wait(30) == 0


@contextmanager
def lock_held(folder: Path) -> Iterator[Holder]:
    """The lock of `folder`'s best-times file held by another process (released at the
    end at the latest)."""
    folder.mkdir(parents=True, exist_ok=True)
    holder = Holder(folder / "best_times.json.lock")
    try:
        yield holder
    finally:
        holder.release()
