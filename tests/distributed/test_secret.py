"""The key that signs work shards: made once per user, private, outside the work folder."""

from __future__ import annotations

import os
import stat
import subprocess
import sys
from pathlib import Path

import pytest

from ecs_tentacles.distributed.secret import SecretUnavailable, secret_path, shard_secret
from ecs_tentacles.distributed.work import WorkFolder

PRINT_KEY = "from ecs_tentacles.distributed.secret import shard_secret; print(shard_secret().hex())"


@pytest.fixture
def state(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("XDG_STATE_HOME", str(tmp_path / "state"))
    return tmp_path / "state" / "ecs_tentacles"


def test_the_key_is_made_once_private_and_kept(state: Path) -> None:
    key = shard_secret()
    assert secret_path() == state / "shard.key"
    assert len(key) == 32 and shard_secret() == key
    assert stat.S_IMODE(os.stat(state).st_mode) == 0o700
    assert stat.S_IMODE(os.stat(state / "shard.key").st_mode) == 0o600
    assert [p.name for p in state.iterdir()] == ["shard.key"]


def test_bakes_starting_at_once_share_one_key(state: Path) -> None:
    starts = [
        subprocess.Popen([sys.executable, "-P", "-c", PRINT_KEY], stdout=subprocess.PIPE, text=True)
        for _ in range(4)
    ]
    keys = {start.communicate(timeout=60)[0] for start in starts}
    assert keys == {f"{shard_secret().hex()}\n"}


@pytest.mark.parametrize(
    ("make", "said"),
    [
        (lambda p: (p.write_bytes(b"k" * 32), p.chmod(0o644)), "readable by other users"),
        (lambda p: (p.write_bytes(b"short"), p.chmod(0o600)), "5 bytes, not 32"),
        (lambda p: os.mkfifo(p, 0o600), "a FIFO, not a regular file"),
    ],
)
def test_a_key_file_that_is_not_private_or_whole_is_refused_naming_it(
    state: Path, make: object, said: str
) -> None:
    state.mkdir(parents=True)
    make(state / "shard.key")  # type: ignore[operator]
    with pytest.raises(SecretUnavailable) as refused:
        shard_secret()
    assert str(refused.value) == (
        f"{state / 'shard.key'}: the shard key is {said}; remove it and a new one is made"
    )


def test_without_a_key_nothing_is_kept_and_one_note_says_so(state: Path, tmp_path: Path) -> None:
    state.parent.mkdir()
    state.write_text("a file where the state folder goes")
    notes: list[str] = []
    work = WorkFolder.open(tmp_path / "work", resume=True, note=notes.append)
    assert work.secret is None and work.kept("0" * 24, "shard 0 (a)") is None
    assert notes == [
        f"ray: {state / 'shard.key'}: cannot read the shard key: not a directory:"
        " kept shards are not used and none are kept for --resume"
    ]
