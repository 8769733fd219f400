"""Opening a file that may lie: a regular file only, never waited on, size-capped.

    with regular_file(path, max_bytes=1 << 20) as handle:   # Unfit: a FIFO, a link, too big
        data = handle.read()
    data = read_regular(path, max_bytes=1 << 20)            # the same, read whole

A FIFO opened for reading blocks until a writer comes; a device never ends; a file
may be far larger than its kind ever is. The path is therefore opened with
`O_NONBLOCK` (and `O_NOFOLLOW` when `follow=False`: the project's own caches and
work shards are never links), checked with `fstat` on the same descriptor (so it
cannot be swapped between check and read) and read at most `max_bytes + 1` bytes.
`FileNotFoundError` and other `OSError`s of opening pass through (callers word them).
`ClosedOnExit` is the base of a reader that holds files (or a worker) open between calls:
`with` gives the reader and closes it however the block ends.
"""

from __future__ import annotations

import abc
import contextlib
import errno
import os
import stat
from collections.abc import Iterator
from types import TracebackType
from typing import BinaryIO, Self

_OPEN = os.O_RDONLY | os.O_NONBLOCK | os.O_NOCTTY | os.O_CLOEXEC


class Unfit(ValueError):
    """Not a regular file of at most the bytes asked; `reason` says why in a few words
    (`a FIFO`, `a symbolic link`, `larger than 1048576 bytes`)."""

    def __init__(self, reason: str) -> None:
        super().__init__(reason)
        self.reason = reason


class TooLarge(Unfit):
    """A regular file larger than the bytes asked (`limit`)."""

    def __init__(self, limit: int) -> None:
        super().__init__(f"larger than {limit} bytes")
        self.limit = limit


class ClosedOnExit(abc.ABC):
    """A reader of files that holds them open until `close()`; as a context manager it
    gives itself and is closed however the `with` block ends."""

    @abc.abstractmethod
    def close(self) -> None:
        """Let go of what the reader holds open (callable more than once)."""

    def __enter__(self) -> Self:
        return self

    def __exit__(
        self,
        kind: type[BaseException] | None,
        error: BaseException | None,
        trace: TracebackType | None,
    ) -> None:
        self.close()


def kind_of(mode: int) -> str:
    """What a file of `st_mode` `mode` is, in a few words (`a regular file`, `a FIFO`)."""
    if stat.S_ISREG(mode):
        return "a regular file"
    if stat.S_ISDIR(mode):
        return "a folder"
    if stat.S_ISFIFO(mode):
        return "a FIFO"
    if stat.S_ISLNK(mode):
        return "a symbolic link"
    return "a device or socket"


@contextlib.contextmanager
def regular_file(
    path: str | os.PathLike[str], max_bytes: int, *, follow: bool = True
) -> Iterator[BinaryIO]:
    """`path` open for reading if it is a regular file of at most `max_bytes` (and not a
    symbolic link unless `follow`); else `Unfit`, the file closed."""
    try:
        descriptor = os.open(path, _OPEN if follow else _OPEN | os.O_NOFOLLOW)
    except OSError as error:
        if not follow and error.errno == errno.ELOOP:
            raise Unfit("a symbolic link") from None
        raise
    try:
        info = os.fstat(descriptor)
        if not stat.S_ISREG(info.st_mode):
            raise Unfit(f"{kind_of(info.st_mode)}, not a regular file")
        if info.st_size > max_bytes:
            raise TooLarge(max_bytes)
        handle = os.fdopen(descriptor, "rb")
    except BaseException:
        os.close(descriptor)
        raise
    with handle:
        yield handle


def read_regular(path: str | os.PathLike[str], max_bytes: int, *, follow: bool = True) -> bytes:
    """The bytes of `path` (`regular_file`'s checks); `TooLarge` also when the file grew
    past `max_bytes` while it was read."""
    with regular_file(path, max_bytes, follow=follow) as handle:
        data = handle.read(max_bytes + 1)
    if len(data) > max_bytes:
        raise TooLarge(max_bytes)
    return data
