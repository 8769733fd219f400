"""Files the project keeps between runs (decomposed meshes, gait clips), sealed when
written and checked when read back: a later run treats them as untrusted input.

    CACHE = SealedCache("meshes", b"ECSTPCS1", ".pieces", max_bytes)
    data = CACHE.seal(key, payload)     # magic, the key's 32 bytes, payload, SHA-256 of all
    data = CACHE.load(key)              # the key's file, read as untrusted; None when
                                        # absent, a link, a FIFO, too large or unreadable
    body = CACHE.opened(key, data, 4)   # the body (magic and key in front) or None
    CACHE.keep(key, payload)            # written whole (`atomic_file`) or not at all

An entry lives in `$XDG_CACHE_HOME/ecs_tentacles/<name>/<key><suffix>` (else
`~/.cache/...`); `key` is a SHA-256 in hex. What the payload holds is its owner's to
check (`opened` only vouches that the file is whole, ours, and of this key).
"""

from __future__ import annotations

import hashlib
import os
import pathlib
from dataclasses import dataclass

from ecs_tentacles.output.atomic import atomic_file
from ecs_tentacles.untrusted.files import Unfit, read_regular

DIGEST = 32  # bytes of a SHA-256


def key_bytes(key: str) -> bytes:
    """The key's 32 bytes as kept in an entry (b"" for a key that is not a SHA-256)."""
    try:
        digest = bytes.fromhex(key)
    except ValueError:
        return b""
    return digest if len(digest) == DIGEST else b""


@dataclass(frozen=True)
class SealedCache:
    """One kind of kept file: its folder's name, first bytes, file suffix, largest size."""

    name: str
    magic: bytes
    suffix: str
    max_bytes: int

    @property
    def head(self) -> int:
        """Bytes before the payload: the magic and the key."""
        return len(self.magic) + DIGEST

    def folder(self) -> pathlib.Path:
        """Where the entries are kept between runs."""
        home = os.path.join(os.path.expanduser("~"), ".cache")
        return pathlib.Path(os.environ.get("XDG_CACHE_HOME") or home) / "ecs_tentacles" / self.name

    def entry(self, key: str) -> pathlib.Path:
        """The file of `key` (a SHA-256 in hex)."""
        return self.folder() / f"{key}{self.suffix}"

    def seal(self, key: str, payload: bytes) -> bytes:
        """An entry's bytes: the magic, the key, `payload` and a SHA-256 of them."""
        body = self.magic + bytes.fromhex(key) + payload
        return body + hashlib.sha256(body).digest()

    def opened(self, key: str, data: bytes, least: int = 0) -> bytes | None:
        """The body of an entry's bytes (magic and key in front, the digest off), or None
        unless it holds `least` payload bytes or more, at most `max_bytes` in all, its
        digest matches, it starts with the magic and names `key`."""
        if not self.head + least + DIGEST <= len(data) <= self.max_bytes:
            return None
        body, digest = data[:-DIGEST], data[-DIGEST:]
        if hashlib.sha256(body).digest() != digest or not body.startswith(self.magic):
            return None
        source = key_bytes(key)
        return body if source and body[len(self.magic) : self.head] == source else None

    def load(self, key: str) -> bytes | None:
        """The bytes of the file of `key`, read as untrusted (a regular file, not followed,
        at most `max_bytes`; `opened` checks them); None when absent, unfit or unreadable."""
        if not key_bytes(key):
            return None
        try:
            return read_regular(self.entry(key), self.max_bytes, follow=False)
        except (OSError, Unfit):  # absent, a link, a FIFO, too large, no permission
            return None

    def keep(self, key: str, payload: bytes) -> None:
        """Write the entry of `key` atomically; a cache that cannot be written is skipped
        silently (the next run makes it again)."""
        if not key_bytes(key):
            return
        try:
            self.folder().mkdir(parents=True, exist_ok=True)
            with atomic_file(self.entry(key)) as handle:
                handle.write(self.seal(key, payload))
        except OSError:  # OutputError included: a full disk, another run's entry first
            pass
