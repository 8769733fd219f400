"""The work folder of a distributed bake: finished shards, kept until the merge.

`take.npz` bakes into `.take.npz.work/` beside it. Each finished shard is written
there atomically as `<key>.npz` (its take's arrays, its contact spheres and its
creatures), keyed by a hash of everything its result depends on: the scene, the
shard's creatures, the bake settings and this package's version. A changed scene or
setting therefore never reuses old work. `--resume` loads the shards found there;
the folder is removed once the merged output is written.

Each shard is signed: `<key>.npz.hmac` beside it holds the HMAC-SHA256 of the shard's
key and every byte of its file, under this user's key (`ecs_tentacles.distributed.
secret`, kept outside the work folder). A shard is read back only once its file is a
regular file of at most `MAX_SHARD_BYTES` whose signature matches, read through the
same descriptor it was checked through; anything else (`ShardUnusable`: changed,
unsigned, truncated, or signed by another user's key) is baked again. The signature
shows that this user's bake wrote these bytes for this key; it does not hide them.
"""

from __future__ import annotations

import contextlib
import hashlib
import hmac
import io
import json
import re
import shutil
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import BinaryIO

import numpy as np

from ecs_tentacles.distributed.secret import SecretUnavailable, shard_secret
from ecs_tentacles.distributed.task import ShardResult
from ecs_tentacles.export.bake import BakePlan
from ecs_tentacles.output.atomic import atomic_file
from ecs_tentacles.take import Take, write_npz
from ecs_tentacles.take.compact import unpacked
from ecs_tentacles.take.read import MAX_HEADER_BYTES, MAX_TAKE_BYTES
from ecs_tentacles.untrusted import bounded_json
from ecs_tentacles.untrusted.files import Unfit, regular_file

_KEY = re.compile(r"^[0-9a-f]{24}\.npz(\.hmac)?$")
MAX_SHARD_BYTES = MAX_TAKE_BYTES  # a shard file larger than a take may be is baked again
_SIGNED = b"ecs_tentacles work shard 1\0"  # what the signature is of, before key and file


class ShardUnusable(ValueError):
    """A kept shard that cannot be used; the message says why, in a few words."""


def work_folder(out: Path) -> Path:
    """`.<name>.work` beside the output `out`."""
    return out.with_name(f".{out.name}.work")


def shard_key(plan: BakePlan, members: list[int], allow_systems: bool) -> str:
    """24 hex digits naming one shard's result under these exact settings."""
    from ecs_tentacles import __version__

    settings = {
        "scene": plan.scene_sha256,
        "members": members,
        "seconds": plan.seconds,
        "fps": plan.fps,
        "sim_fps": plan.sim_fps,
        "seed": plan.seed,
        "allow_systems": allow_systems,
        "version": __version__,
    }
    text = json.dumps(settings, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:24]


def _signer(secret: bytes, key: str) -> hmac.HMAC:
    signer = hmac.new(secret, _SIGNED, hashlib.sha256)
    signer.update(key.encode() + b"\0")
    return signer


def signature(secret: bytes, key: str, data: bytes | memoryview) -> str:
    """The signature (hex) of `data`, the file of the shard `key`, under `secret`."""
    signer = _signer(secret, key)
    signer.update(data)
    return signer.hexdigest()


def save_shard(folder: Path, key: str, result: ShardResult, secret: bytes) -> None:
    """Write one finished shard and then its signature, each atomically."""
    folder.mkdir(exist_ok=True)
    arrays = result.take.arrays()
    arrays["spheres"] = result.spheres
    arrays["members"] = np.asarray(result.members, dtype=np.int64)
    buffer = io.BytesIO()  # signed as written: nothing in the folder is read back
    write_npz(buffer, arrays)
    data = buffer.getbuffer()
    with contextlib.suppress(FileNotFoundError):  # an old signature never meets new bytes
        (folder / f"{key}.npz.hmac").unlink()
    with atomic_file(folder / f"{key}.npz") as handle:
        handle.write(data)
    with atomic_file(folder / f"{key}.npz.hmac") as handle:
        handle.write(f"{signature(secret, key, data)}\n".encode())


def load_shard(folder: Path, key: str, secret: bytes) -> ShardResult | None:
    """The shard saved under `key`; None when there is none; `ShardUnusable` when one
    is there but is not this user's bake's, unchanged, or does not read."""
    path = folder / f"{key}.npz"
    try:
        path.lstat()
    except FileNotFoundError:
        return None
    with _regular(folder / f"{key}.npz.hmac", 256, "its signature") as handle:
        signature = handle.read().strip()
    with _regular(path, MAX_SHARD_BYTES, "it") as handle:
        signer = _signer(secret, key)
        for block in iter(lambda: handle.read(1 << 20), b""):
            signer.update(block)
        if not hmac.compare_digest(signer.hexdigest().encode(), signature):
            raise ShardUnusable(
                "it changed after this user's bake wrote it (the signature differs)"
            )
        handle.seek(0)
        try:
            return _parse(handle)
        except ShardUnusable:
            raise
        except Exception as error:  # signed but unreadable: a bug of ours, baked again
            text = " ".join(str(error).split())[:200]
            raise ShardUnusable(f"it does not read ({type(error).__name__}: {text})") from None


@contextlib.contextmanager
def _regular(path: Path, limit: int, what: str) -> Iterator[BinaryIO]:
    """`path` open for reading if it is a regular file (not followed if a link) of at
    most `limit` bytes, else `ShardUnusable` (a FIFO is never waited on)."""
    with contextlib.ExitStack() as stack:
        try:
            handle = stack.enter_context(regular_file(path, limit, follow=False))
        except FileNotFoundError:
            raise ShardUnusable(f"{what} is missing") from None
        except Unfit as unfit:
            raise ShardUnusable(f"{what} is {unfit.reason}") from None
        except OSError as error:
            raise ShardUnusable(f"{what} cannot be opened ({error.strerror})") from None
        yield handle


def _parse(handle: BinaryIO) -> ShardResult:
    with np.load(handle, allow_pickle=False) as data:
        text = bytes(data["header"]).decode()
        header = unpacked(bounded_json.loads(text, "header", max_bytes=MAX_HEADER_BYTES))
        own = ("header", "spheres", "members")
        arrays = {k: data[k] for k in data.files if k not in own}
        take = Take.from_arrays(header, arrays)
        result = ShardResult(data["members"].tolist(), take, data["spheres"])
    problem = take.problem()
    if problem:
        raise ShardUnusable(f"it does not read ({problem})")
    return result


@dataclass
class WorkFolder:
    """A bake's work folder: `keep` saves finished shards, `kept` gives them back on
    --resume; `secret` None (no key to be had) keeps and gives back nothing."""

    folder: Path
    resume: bool
    secret: bytes | None
    note: Callable[[str], None]

    @classmethod
    def open(cls, folder: Path, *, resume: bool, note: Callable[[str], None]) -> WorkFolder:
        """The work folder `folder`, with this user's key (one `note` when there is none)."""
        try:
            secret: bytes | None = shard_secret()
        except SecretUnavailable as error:
            kept = "kept shards are not used and none are kept" if resume else "no shard is kept"
            note(f"ray: {error}: {kept} for --resume")
            secret = None
        return cls(folder, resume, secret, note)

    def keep(self, key: str, result: ShardResult) -> None:
        """Save a finished shard (signed), when there is a key."""
        if self.secret is not None:
            save_shard(self.folder, key, result, self.secret)

    def kept(self, key: str, label: str) -> ShardResult | None:
        """The shard kept under `key` if resuming and it is there, signed and sound; one
        that is not is named (`label`) in a `note` and left to be baked again."""
        if not self.resume or self.secret is None:
            return None
        try:
            return load_shard(self.folder, key, self.secret)
        except ShardUnusable as why:
            self.note(f"ray: {label}: kept result not used: {why}; baking it again")
            return None


def remove_work(folder: Path) -> None:
    """Delete the work folder if it holds only shard results (and their partials)."""
    if not folder.is_dir():
        return
    names = [p.name for p in folder.iterdir()]
    if all(_KEY.match(n) or ".partial" in n for n in names):
        shutil.rmtree(folder, ignore_errors=True)
    else:
        for name in filter(_KEY.match, names):
            with contextlib.suppress(OSError):
                (folder / name).unlink()
