"""Opening a file that may lie: FIFOs, devices, folders and links refused at once."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from ecs_tentacles.untrusted.files import TooLarge, Unfit, read_regular, regular_file


def test_a_regular_file_within_its_size_reads_whole(tmp_path: Path) -> None:
    path = tmp_path / "entry"
    path.write_bytes(b"x" * 100)
    assert read_regular(path, 100) == b"x" * 100
    with regular_file(path, 100) as handle:
        assert handle.read(10) == b"x" * 10


def test_one_byte_more_is_too_large_and_says_the_limit(tmp_path: Path) -> None:
    path = tmp_path / "entry"
    path.write_bytes(b"x" * 101)
    with pytest.raises(TooLarge, match=r"^larger than 100 bytes$") as refused:
        read_regular(path, 100)
    assert refused.value.limit == 100


def test_a_fifo_no_one_writes_is_refused_without_waiting(tmp_path: Path) -> None:
    fifo = tmp_path / "entry"
    os.mkfifo(fifo)
    with pytest.raises(Unfit, match=r"^a FIFO, not a regular file$"):
        read_regular(fifo, 100)  # a plain open() would block here for ever


@pytest.mark.parametrize(("path", "kind"), [("/dev/zero", "a device or socket"), ("/", "a folder")])
def test_devices_and_folders_are_not_read(path: str, kind: str) -> None:
    with pytest.raises(Unfit, match=f"^{kind}, not a regular file$"):
        read_regular(path, 100)


def test_a_link_is_followed_only_when_asked(tmp_path: Path) -> None:
    target = tmp_path / "target"
    target.write_bytes(b"kept")
    link = tmp_path / "link"
    link.symlink_to(target)
    assert read_regular(link, 100) == b"kept"
    with pytest.raises(Unfit, match=r"^a symbolic link$"):
        read_regular(link, 100, follow=False)


def test_a_missing_file_is_the_callers_to_word(tmp_path: Path) -> None:
    with pytest.raises(FileNotFoundError):
        read_regular(tmp_path / "absent", 100)
