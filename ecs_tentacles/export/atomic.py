"""Atomic file output: write beside the target, then rename over it in one step.

    with atomic_output("take.npz") as temporary:
        write_everything(temporary)       # any path-taking writer (numpy, USD, json)

The temporary file sits in the target's folder (so the rename never crosses file
systems), is flushed to disk, then `os.replace`d onto the target. If anything fails
or the user presses Ctrl-C, the temporary file is removed and the target is left as
it was: a reader never sees half a file where the output should be. A process killed
outright (SIGKILL, power loss) can leave the hidden temporary file behind, never a
partial target.
"""

from __future__ import annotations

import contextlib
import os
import secrets
from collections.abc import Iterator
from pathlib import Path


def temporary_sibling(path: Path) -> Path:
    """A new, empty, hidden file beside `path` that keeps its suffix (writers pick formats by it).

    `take.usda` -> `.take.3f9a1c2e.partial.usda`. Created with the user's umask, like
    the target would be.
    """
    while True:
        candidate = path.with_name(f".{path.stem}.{secrets.token_hex(4)}.partial{path.suffix}")
        try:
            with open(candidate, "xb"):
                return candidate
        except FileExistsError:  # pragma: no cover - 32 random bits collided
            continue


def _fsync_file(path: Path) -> None:
    with open(path, "rb+") as handle:
        os.fsync(handle.fileno())


def _fsync_folder(folder: Path) -> None:
    """Make the rename itself durable (POSIX; a no-op where folders cannot be opened)."""
    try:
        descriptor = os.open(folder, os.O_RDONLY)
    except OSError:  # pragma: no cover - e.g. Windows
        return
    try:
        os.fsync(descriptor)
    except OSError:  # pragma: no cover - some file systems refuse
        pass
    finally:
        os.close(descriptor)


@contextlib.contextmanager
def atomic_output(target: str | os.PathLike[str]) -> Iterator[Path]:
    """Yield a temporary path to write; on success move it onto `target` atomically.

    On any exception (KeyboardInterrupt included) the temporary file is deleted, the
    target is untouched and the exception propagates.
    """
    path = Path(target)
    temporary = temporary_sibling(path)
    try:
        yield temporary
        _fsync_file(temporary)
        os.replace(temporary, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            temporary.unlink()
        raise
    _fsync_folder(path.parent)
