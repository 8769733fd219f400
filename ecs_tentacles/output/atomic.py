"""The one output writer: every file the project writes appears whole or not at all.

    with atomic_output("take.npz") as temporary:    # for writers that take a path
        write_everything(temporary)                 # (numpy, USD, ffmpeg)
    with atomic_file("shot.png") as handle:         # for writers that take a file
        handle.write(data)

The temporary file sits in the target's folder (so the rename never crosses file
systems) under a random name, `.take.3f9a1c2e.partial.npz`, created exclusively
(`O_CREAT | O_EXCL | O_NOFOLLOW`): a file or symlink planted at that name is never
opened or followed, another name is drawn. When the writer is done the file is
fsynced and renamed onto the target, then the folder is fsynced.

- Any exception (KeyboardInterrupt included, and SIGTERM once the CLI's handler turns
  it into an exception) removes the temporary file and leaves the target as it was.
  Once renamed, a file is whole and stays: a stop that lands during the rename waits
  until the run has noted the file as written (`claimed_outputs`), and the command line
  then reports it as kept, not as removed (exit 0 when every output was written).
- Two runs writing one target at the same time: exactly one wins. Each remembers what
  the target was when it started (`claim(target)`, which the CLI calls for every
  output path as it reads its arguments, long before a bake has anything to write;
  without a claim, when the writing starts); at the end, under a lock on the folder,
  a run whose target changed meanwhile discards its own output and raises
  `OutputConflict` instead of overwriting the other run's file.
- A process killed outright (SIGKILL, power loss) never leaves a partial target. Writers
  that take a file (`atomic_file`: takes, glb, PNG) write an unnamed file on Linux
  (`O_TMPFILE`), named only when it is finished, so a killed one leaves nothing at all;
  elsewhere, and for writers that take a path (USD's own `.take.3f9a1c2e.partial.XXXXXX`
  too), a hidden temporary file can stay behind: the next write to the same target
  removes such leftovers older than a day (`STALE_SECONDS`) and says so on stderr.
"""

from __future__ import annotations

import contextlib
import errno
import fcntl
import os
import re
import secrets
import stat
import sys
import time
from collections.abc import Iterator
from pathlib import Path
from typing import BinaryIO

STALE_SECONDS = 24 * 3600  # a partial file older than this is a dead run's leftover
_CREATE = os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW | os.O_CLOEXEC

Identity = tuple[int, int, int, int, int] | None


class OutputError(OSError):
    """An output could not be written; the message is one line naming the file."""


_DISK_FULL = (errno.ENOSPC, errno.EDQUOT, errno.EFBIG)


def disk_full(target: Path, error: BaseException) -> OutputError | None:
    """`error` (a writer's, while writing `target`) as one line naming `target` when the
    disk or quota is full or the file too large, else None. Writers say it their way:
    an OSError's errno (numpy, zipfile, JSON), or only in the text (USD's
    `Tf.ErrorException` repeats "No space left on device" for every buffer it flushes)."""
    if isinstance(error, OutputError):
        return None
    code = error.errno if isinstance(error, OSError) else None
    if code not in _DISK_FULL:
        text = str(error)
        code = next((c for c in _DISK_FULL if os.strerror(c) in text), None)
        if code is None or not isinstance(error, Exception):
            return None
    return OutputError(f"{target}: cannot write: {os.strerror(code).lower()}; nothing written")


class OutputConflict(OutputError):
    """Another program replaced the target while this run was writing it."""


def temporary_name(path: Path, token: str) -> Path:
    """`take.usda` + token -> `.take.<token>.partial.usda` (the suffix picks writers' formats)."""
    return path.with_name(f".{path.stem}.{token}.partial{path.suffix}")


def _create_exclusive(path: Path) -> tuple[Path, int]:
    """A new, empty temporary file beside `path` and its open descriptor (never a symlink)."""
    while True:
        candidate = temporary_name(path, secrets.token_hex(4))
        try:
            return candidate, os.open(candidate, _CREATE, 0o666)  # the umask applies
        except FileExistsError:  # a leftover or a planted file or symlink: draw again
            continue
        except OSError as error:
            raise OutputError(f"{path}: cannot write: {error.strerror or error}") from None


def _link_descriptor(descriptor: int, name: Path) -> bool:
    """Give the unnamed file `descriptor` the name `name` (`linkat`): through /proc, else
    by `AT_EMPTY_PATH`; False where neither is allowed (FileExistsError: name taken)."""
    try:
        os.link(f"/proc/self/fd/{descriptor}", name, follow_symlinks=True)
        return True
    except FileExistsError:
        raise
    except OSError:
        pass
    import ctypes

    libc = ctypes.CDLL(None, use_errno=True)
    at_fdcwd, at_empty_path = -100, 0x1000
    if libc.linkat(descriptor, b"", at_fdcwd, os.fsencode(name), at_empty_path) == 0:
        return True
    if ctypes.get_errno() == errno.EEXIST:
        raise FileExistsError(errno.EEXIST, os.strerror(errno.EEXIST), str(name))
    return False


def _create_unnamed(path: Path) -> int | None:
    """An unnamed file in `path`'s folder (Linux `O_TMPFILE`), or None where the system
    or the file system has none (the caller then makes a named one)."""
    flag = getattr(os, "O_TMPFILE", None)
    if flag is None or not os.path.isdir("/proc/self/fd"):
        return None
    try:
        return os.open(path.parent, flag | os.O_WRONLY | os.O_CLOEXEC, 0o666)
    except OSError as error:
        if error.errno in (errno.EOPNOTSUPP, errno.EISDIR, errno.EINVAL, errno.ENOENT):
            return None
        raise OutputError(f"{path}: cannot write: {error.strerror or error}") from None


def partial_pattern(path: Path) -> re.Pattern[str]:
    """Names of this tool's temporary files for `path`: ours, USD's and the old fixed one."""
    stem, suffix = re.escape(path.stem), re.escape(path.suffix)
    return re.compile(
        rf"^\.{stem}(?:\.[0-9a-f]{{8}}\.partial(?:{suffix}|\.[A-Za-z0-9]{{6}})|\.partial{suffix})$"
    )


def remove_stale_partials(path: Path, now: float | None = None) -> list[Path]:
    """Delete this tool's temporary files for `path` older than a day; report each on stderr.

    Only regular files owned by this user are touched (never a symlink's target).
    """
    pattern = partial_pattern(path)
    now = time.time() if now is None else now
    removed: list[Path] = []
    try:
        names = os.listdir(path.parent)
    except OSError:
        return removed
    for name in names:
        if not pattern.match(name):
            continue
        candidate = path.parent / name
        try:
            info = candidate.lstat()
            if not stat.S_ISREG(info.st_mode) or info.st_uid != os.getuid():
                continue
            if now - info.st_mtime < STALE_SECONDS:
                continue  # perhaps a run still writing
            candidate.unlink()
        except OSError:
            continue
        hours = (now - info.st_mtime) / 3600
        print(
            f"note: {path}: removed {name}, a partial file left by an interrupted run"
            f" {hours:.0f} h ago",
            file=sys.stderr,
        )
        removed.append(candidate)
    return removed


def _identity(path: Path) -> Identity:
    """What the target is now (None: absent); any replacement changes it."""
    try:
        info = path.lstat()
    except FileNotFoundError:
        return None
    return (info.st_dev, info.st_ino, info.st_size, info.st_mtime_ns, info.st_ctime_ns)


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
def _folder_lock(folder: Path) -> Iterator[None]:
    """Hold an exclusive flock on `folder` (brief: only around check + rename)."""
    try:
        descriptor = os.open(folder, os.O_RDONLY | os.O_DIRECTORY | os.O_CLOEXEC)
    except OSError:  # pragma: no cover - a folder that cannot be opened: no lock
        yield
        return
    try:
        with contextlib.suppress(OSError):  # file systems without flock: no lock
            fcntl.flock(descriptor, fcntl.LOCK_EX)
        yield
    finally:
        os.close(descriptor)  # releases the lock


_claims: dict[str, Identity] = {}  # absolute target path -> what it was when claimed
_outputs: dict[str, bool] = {}  # every target claimed in this run -> written since


def _claim_key(target: str | os.PathLike[str]) -> str:
    return os.path.abspath(target)


def claim(target: str | os.PathLike[str]) -> None:
    """Remember what `target` is now: the next write to it in this process fails with
    `OutputConflict` if another program wrote it in between (call as a run starts).

    Raises OutputError when the folder does not exist or is not writable, so a long
    run that could never save its output does not start.
    """
    path = Path(target)
    folder = path.parent
    if not folder.is_dir():
        raise OutputError(f"{path}: folder {str(folder)!r} does not exist")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise OutputError(f"{path}: cannot write in folder {str(folder)!r} (permission denied)")
    _claims[_claim_key(path)] = _identity(path)
    _outputs[_claim_key(path)] = False


def release_claims() -> None:
    """Forget every claim (a new run in the same process starts from scratch)."""
    _claims.clear()
    _outputs.clear()


def claimed_outputs() -> tuple[list[Path], list[Path]]:
    """The outputs claimed in this run: those written whole (renamed into place), and
    those not (yet), each in the order claimed."""
    written = [Path(key) for key, done in _outputs.items() if done]
    return written, [Path(key) for key, done in _outputs.items() if not done]


class AtomicOutput:
    """One output in progress: `open()` the temporary file, then `commit()` or `discard()`.

    `atomic_output` wraps this for `with` blocks; long-lived writers (a video recorded
    over many frames) hold one directly.
    """

    def __init__(self, target: str | os.PathLike[str]):
        self.target = Path(target)
        self.temporary: Path | None = None
        self.unnamed: int | None = None  # the descriptor of an unnamed file (O_TMPFILE)
        self._before: Identity = None
        self._created: tuple[int, int] | None = None

    def open(self, *, unnamed: bool = False) -> int:
        """Clean stale leftovers, create the temporary file; returns its open descriptor.

        `unnamed`: where the system allows (Linux `O_TMPFILE`), a file with no name in the
        folder until `commit` links it there, so even a killed process leaves nothing
        behind; the caller keeps the descriptor open until `commit`."""
        remove_stale_partials(self.target)
        key = _claim_key(self.target)
        self._before = _claims.pop(key) if key in _claims else _identity(self.target)
        descriptor = _create_unnamed(self.target) if unnamed else None
        if descriptor is None:
            self.temporary, descriptor = _create_exclusive(self.target)
        else:
            self.unnamed = descriptor
        info = os.fstat(descriptor)
        self._created = (info.st_dev, info.st_ino)
        return descriptor

    def _link_unnamed(self) -> None:
        """Give the unnamed file its temporary name in the target's folder (fsynced first)."""
        assert self.unnamed is not None
        descriptor, self.unnamed = self.unnamed, None
        with self.discarded_on_error():
            _stop_if_asked()
            os.fsync(descriptor)
            while True:
                candidate = temporary_name(self.target, secrets.token_hex(4))
                try:
                    linked = _link_descriptor(descriptor, candidate)
                except FileExistsError:
                    continue
                if linked:
                    self.temporary = candidate
                    return
                break
            # no way to name it here: a copy into a named temporary file
            self.temporary, copy = _create_exclusive(self.target)
            try:
                size = os.fstat(descriptor).st_size
                done = 0
                while done < size:
                    done += os.copy_file_range(descriptor, copy, size - done, done, done)
                os.fsync(copy)
                info = os.fstat(copy)
                self._created = (info.st_dev, info.st_ino)
            finally:
                os.close(copy)

    def commit(self, *, same_file: bool = False) -> Path:
        """Fsync the finished temporary file and rename it onto the target.

        `same_file`: the writer wrote through our descriptor, so the file must still be
        the one we created (path-based writers such as USD may replace it by rename).
        Raises `OutputConflict` (and discards) if the target changed since `open()`.
        """
        if self.unnamed is not None:
            self._link_unnamed()
        assert self.temporary is not None, "open() first"
        temporary = self.temporary
        try:
            descriptor = os.open(temporary, os.O_RDONLY | os.O_NOFOLLOW | os.O_CLOEXEC)
        except OSError as error:
            self.discard()
            raise OutputError(
                f"{self.target}: the temporary file {temporary.name} was"
                f" removed or replaced while writing ({error.strerror})"
            ) from None
        try:
            with self.discarded_on_error():
                _stop_if_asked()
                info = os.fstat(descriptor)
                if not stat.S_ISREG(info.st_mode) or (
                    same_file and (info.st_dev, info.st_ino) != self._created
                ):
                    raise OutputError(
                        f"{self.target}: the temporary file {temporary.name} was replaced"
                        " while writing; nothing written"
                    )
                os.fsync(descriptor)
        finally:
            os.close(descriptor)
        # A stop landing as the file goes into place waits until the run has noted it
        # there: the command line then says it was kept (`claimed_outputs`), never that
        # partial outputs were removed while the whole file stays.
        with _stops_deferred():
            with _folder_lock(self.target.parent):
                if _identity(self.target) != self._before:
                    self.discard()
                    raise OutputConflict(
                        f"{self.target}: another program wrote this file after this run"
                        " started; kept theirs, discarded ours"
                    )
                try:
                    os.replace(temporary, self.target)
                except BaseException:
                    self.discard()
                    raise
                self.temporary = None
                key = _claim_key(self.target)
                if key in _outputs:
                    _outputs[key] = True
            _fsync_folder(self.target.parent)
        return self.target

    @contextlib.contextmanager
    def discarded_on_error(self) -> Iterator[None]:
        """On any exception inside: the temporary file removed, the target untouched, and
        a full disk or quota said in one line naming the target (`disk_full`)."""
        try:
            yield
        except BaseException as error:
            self.discard()
            full = disk_full(self.target, error)
            if full is not None:
                raise full from None
            raise

    def discard(self) -> None:
        """Remove the temporary file (if any); the target stays as it was."""
        if self.temporary is not None:
            with contextlib.suppress(FileNotFoundError):
                self.temporary.unlink()
            self.temporary = None


def _stops_deferred() -> contextlib.AbstractContextManager[None]:
    """`ecs_tentacles.stops.deferred()` when the command line loaded it (looked up, as
    in `_stop_if_asked`), else nothing: a stopping signal inside waits for its end."""
    stops = sys.modules.get("ecs_tentacles.stops")
    return stops.deferred() if stops is not None else contextlib.nullcontext()


def _stop_if_asked() -> None:
    """Raise a Ctrl-C or SIGTERM that arrived and was swallowed by some library before
    reaching the command line (`ecs_tentacles.stops.check`): nothing is committed then.
    Looked up, not imported: this module needs only the standard library (Blender's
    Python loads it on its own, `tools/blender_import.py`)."""
    stops = sys.modules.get("ecs_tentacles.stops")
    if stops is not None:
        stops.check()


@contextlib.contextmanager
def atomic_output(target: str | os.PathLike[str]) -> Iterator[Path]:
    """Yield a temporary path to write; on success move it onto `target` atomically.

    On any exception (KeyboardInterrupt included) the temporary file is deleted, the
    target is untouched and the exception propagates.
    """
    output = AtomicOutput(target)
    os.close(output.open())
    assert output.temporary is not None
    with output.discarded_on_error():
        yield output.temporary
    output.commit()


@contextlib.contextmanager
def atomic_file(target: str | os.PathLike[str]) -> Iterator[BinaryIO]:
    """Yield the exclusive temporary file, open for binary writing; then as `atomic_output`.

    The writer never opens a path itself, so nothing planted in the folder is followed.
    """
    output = AtomicOutput(target)
    descriptor = output.open(unnamed=True)
    # a full disk may show only when the buffer is flushed: inside, so it is one line
    with output.discarded_on_error(), os.fdopen(descriptor, "wb") as handle:
        yield handle
        handle.flush()
        output.commit(same_file=True)  # the file still open: an unnamed one is linked
