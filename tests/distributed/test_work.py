"""Kept work shards are read back only when this user's bake signed them, unchanged;
anything else is refused with the reason (and baked again by the driver). No Ray here."""

from __future__ import annotations

import io
import json
import os
from pathlib import Path

import numpy as np
import pytest

from ecs_tentacles.creator.crowd import crowd_scene
from ecs_tentacles.distributed.secret import shard_secret
from ecs_tentacles.distributed.task import ShardResult, bake_shard
from ecs_tentacles.distributed.work import (
    ShardUnusable,
    WorkFolder,
    load_shard,
    remove_work,
    save_shard,
    signature,
)
from ecs_tentacles.export.bake import BakePlan
from ecs_tentacles.take import write_npz

KEY = "0123456789abcdef01234567"  # as `shard_key` names shards: 24 hex digits
CHANGED = "it changed after this user's bake wrote it (the signature differs)"


@pytest.fixture(scope="module")
def shard() -> ShardResult:
    plan = BakePlan.make(crowd_scene(2, seed=1), seconds=0.1, fps=30)
    return bake_shard(plan, [1])


def _arrays(result: ShardResult) -> dict[str, np.ndarray]:
    return {**result.take.arrays(), "spheres": result.spheres, "members": np.array([1])}


def _file(arrays: dict[str, np.ndarray], header: str | None = None) -> bytes:
    """A shard file of `arrays`, its header replaced by the JSON text `header` if given."""
    if header is not None:
        arrays = {**arrays, "header": np.frombuffer(header.encode(), np.uint8)}
    buffer = io.BytesIO()
    write_npz(buffer, arrays)
    return buffer.getvalue()


def test_a_saved_shard_reads_back_whole(shard: ShardResult, tmp_path: Path) -> None:
    secret = shard_secret()
    save_shard(tmp_path, KEY, shard, secret)
    assert sorted(p.name for p in tmp_path.iterdir()) == [f"{KEY}.npz", f"{KEY}.npz.hmac"]
    back = load_shard(tmp_path, KEY, secret)
    assert back is not None and back.members == [1]
    for name, array in _arrays(shard).items():
        np.testing.assert_array_equal(_arrays(back)[name], array)
    assert load_shard(tmp_path, "f" * 24, secret) is None  # none kept: nothing to say
    remove_work(tmp_path)
    assert not tmp_path.exists()


def _moved(arrays: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    return {**arrays, "pos": arrays["pos"] + np.float32(5.0)}  # every body 5 m along x, y, z


@pytest.mark.parametrize(
    ("case", "said"),
    [
        ("every body moved 5 m", CHANGED),
        ("a 400-digit fps", CHANGED),
        ("a header nested 100000 deep", CHANGED),
        ("signed with another user's key", CHANGED),
        ("its signature removed", "its signature is missing"),
        ("a FIFO", "it is a FIFO, not a regular file"),
        ("a symbolic link", "it is a symbolic link"),
        ("a folder", "it is a folder, not a regular file"),
    ],
)
def test_a_changed_or_strange_shard_is_refused_with_its_reason(
    shard: ShardResult, tmp_path: Path, case: str, said: str
) -> None:
    secret = shard_secret()
    save_shard(tmp_path, KEY, shard, b"k" * 32 if "another" in case else secret)
    path = tmp_path / f"{KEY}.npz"
    header = json.loads(shard.take.arrays()["header"].tobytes())
    if case == "every body moved 5 m":
        path.write_bytes(_file(_moved(_arrays(shard))))
    elif case == "a 400-digit fps":
        path.write_bytes(_file(_arrays(shard), json.dumps({**header, "fps": 10**399})))
    elif case == "a header nested 100000 deep":
        path.write_bytes(_file(_arrays(shard), "[" * 100_000 + "]" * 100_000))
    elif case == "its signature removed":
        (tmp_path / f"{KEY}.npz.hmac").unlink()
    elif case in ("a FIFO", "a symbolic link", "a folder"):
        path.unlink()
        if case == "a FIFO":
            os.mkfifo(path)  # opened without waiting for a writer that never comes
        elif case == "a symbolic link":
            path.symlink_to("/dev/zero")
        else:
            path.mkdir()
    with pytest.raises(ShardUnusable) as refused:
        load_shard(tmp_path, KEY, secret)
    assert str(refused.value) == said


@pytest.mark.parametrize(
    ("header", "said"),
    [
        ('{"fps": 1' + "0" * 399 + "}", "header.fps: a number of 400 characters, at most 100"),
        ("[" * 100_000 + "]" * 100_000, "header: nested deeper than 64 levels"),
    ],
)
def test_a_signed_shard_that_does_not_read_is_refused_not_raised(
    shard: ShardResult, tmp_path: Path, header: str, said: str
) -> None:
    """Signed with this user's key (a bug of ours, or whoever holds the key): no crash."""
    secret = shard_secret()
    data = _file(_arrays(shard), header)
    (tmp_path / f"{KEY}.npz").write_bytes(data)
    (tmp_path / f"{KEY}.npz.hmac").write_text(signature(secret, KEY, data))
    with pytest.raises(ShardUnusable) as refused:
        load_shard(tmp_path, KEY, secret)
    assert str(refused.value) == f"it does not read (JsonLimit: {said})"


def test_the_work_folder_names_a_refused_shard_in_one_note(
    shard: ShardResult, tmp_path: Path
) -> None:
    notes: list[str] = []
    work = WorkFolder.open(tmp_path, resume=True, note=notes.append)
    work.keep(KEY, shard)
    (tmp_path / f"{KEY}.npz").write_bytes(_file(_moved(_arrays(shard))))
    assert work.kept(KEY, "shard 1 (b)") is None
    assert notes == [f"ray: shard 1 (b): kept result not used: {CHANGED}; baking it again"]
