"""The key that signs a distributed bake's work shards, kept outside the work folder.

    key = shard_secret()   # 32 bytes; raises SecretUnavailable (one line) if it cannot

Reads, and on first use writes, `shard.key` in this user's state folder (`platformdirs`:
`~/.local/state/ecs_tentacles/` on Linux, under `$XDG_STATE_HOME` when that is set):
32 random bytes, made by `secrets`, in a file of mode 0600 in a folder of mode 0700.
It is written to a temporary file and linked into place, so two bakes starting at once
end up with one key, never a half-written one.

Work shards sit beside the output, where other people or programs may write; the key
does not, so a shard changed there cannot be signed again (`ecs_tentacles.distributed.
work`). A key file that is not a regular file of this user's, is readable by others or
is not 32 bytes is refused (the message names it: remove it and a new one is made).
"""

from __future__ import annotations

import contextlib
import os
import secrets
from pathlib import Path

from platformdirs import user_state_dir

from ecs_tentacles.untrusted.files import TooLarge, Unfit, regular_file

FILE = "shard.key"
SIZE = 32


class SecretUnavailable(OSError):
    """The key cannot be read or made; the message is one line naming the file."""


def secret_path() -> Path:
    """Where the key is (or will be)."""
    return Path(user_state_dir("ecs_tentacles", appauthor=False)) / FILE


def shard_secret() -> bytes:
    """This user's key, made on first use."""
    path = secret_path()
    try:
        return _read(path)
    except FileNotFoundError:
        pass
    try:
        _create(path)
    except OSError as error:
        raise SecretUnavailable(f"{path}: cannot make the shard key: {_reason(error)}") from None
    return _read(path)


def _read(path: Path) -> bytes:
    try:
        with regular_file(path, SIZE, follow=False) as handle:
            info = os.fstat(handle.fileno())
            problem = (
                "not this user's"
                if info.st_uid != os.getuid()
                else "readable by other users"
                if info.st_mode & 0o077
                else None
            )
            data = b"" if problem else handle.read(SIZE + 1)
    except FileNotFoundError:
        raise
    except TooLarge:
        problem = f"larger than {SIZE} bytes"
    except Unfit as unfit:
        problem = unfit.reason
    except OSError as error:
        raise SecretUnavailable(f"{path}: cannot read the shard key: {_reason(error)}") from None
    if problem is None and len(data) != SIZE:
        problem = f"{len(data)} bytes, not {SIZE}"
    if problem:
        raise SecretUnavailable(
            f"{path}: the shard key is {problem}; remove it and a new one is made"
        )
    return data


def _create(path: Path) -> None:
    """Write a new key beside `path` and link it there, unless another process did first."""
    path.parent.mkdir(mode=0o700, parents=True, exist_ok=True)
    temporary = path.with_name(f".{FILE}.{secrets.token_hex(4)}")
    flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW | os.O_CLOEXEC
    descriptor = os.open(temporary, flags, 0o600)
    try:
        with os.fdopen(descriptor, "wb") as handle:
            handle.write(secrets.token_bytes(SIZE))
            handle.flush()
            os.fsync(handle.fileno())
        with contextlib.suppress(FileExistsError):  # another bake made one first: theirs
            os.link(temporary, path)
    finally:
        with contextlib.suppress(FileNotFoundError):
            temporary.unlink()


def _reason(error: OSError) -> str:
    return (error.strerror or str(error)).lower()
