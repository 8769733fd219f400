"""Clips kept between runs: read back bit for bit, and never trusted."""

from __future__ import annotations

import pathlib
from typing import Any

import numpy as np
import pytest
from numpy.testing import assert_array_equal

from ecs_tentacles.clips import disk
from ecs_tentacles.clips.cache import ClipCache, _morphology, recording_input
from ecs_tentacles.clips.clips import GaitClips
from ecs_tentacles.scene.load import load_scene

SMALL = {"count": 4, "links": 5}
QUICK: dict[str, Any] = {"warmup": 1.0, "seconds": 2.5, "loop": (0.5, 2.0)}  # short ones


def _creature() -> tuple[dict[str, Any], dict[str, Any]]:
    scene = load_scene({"version": 1, "creatures": [{"name": "a", "tentacles": SMALL}]})
    return scene["creatures"][0], scene["physics"]


def _same(a: GaitClips, b: GaitClips) -> None:
    assert (a.key, a.bodies, a.seconds, a.store_lag) == (b.key, b.bodies, b.seconds, b.store_lag)
    for x, y in ((a.idle, b.idle), (a.crawl, b.crawl)):
        assert (x.kind, x.dt, x.speed, x.mismatch, x.span) == (
            y.kind, y.dt, y.speed, y.mismatch, y.span,
        )  # fmt: skip
        for name in ("pos", "quat", "qpos", "qvel"):
            assert_array_equal(getattr(x, name), getattr(y, name))


@pytest.fixture
def recorded(
    tmp_path: pathlib.Path, monkeypatch: pytest.MonkeyPatch
) -> tuple[GaitClips, pathlib.Path]:
    """Clips recorded by a cache that keeps them, and the file they were kept in."""
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    creature, physics = _creature()
    clips = ClipCache(disk=True, **QUICK).get(creature, physics)
    (kept,) = (tmp_path / "ecs_tentacles" / "clips").iterdir()
    return clips, kept


def _read_again() -> GaitClips:
    creature, physics = _creature()
    return ClipCache(disk=True, **QUICK).get(creature, physics)


def test_a_new_process_reads_the_kept_clips_bit_for_bit_and_records_nothing(
    recorded: tuple[GaitClips, pathlib.Path], monkeypatch: pytest.MonkeyPatch
) -> None:
    clips, kept = recorded
    assert kept.suffix == ".clips" and kept.stat().st_size > 10_000

    def refuse(*args: Any, **kwargs: Any) -> GaitClips:
        raise AssertionError("recorded again")

    monkeypatch.setattr(GaitClips, "record", refuse)
    again = _read_again()
    _same(again, clips)
    assert again.kept and not clips.kept


@pytest.mark.parametrize("damage", ["flipped", "truncated", "link", "fifo", "renamed"])
def test_a_damaged_or_strange_entry_is_recorded_again(
    recorded: tuple[GaitClips, pathlib.Path], damage: str
) -> None:
    clips, kept = recorded
    data = kept.read_bytes()
    if damage == "flipped":
        kept.write_bytes(data[:5000] + bytes([data[5000] ^ 1]) + data[5001:])
    elif damage == "truncated":
        kept.write_bytes(data[: len(data) // 2])
    elif damage in ("link", "fifo"):
        aside = kept.with_name("aside")
        kept.rename(aside)
        kept.symlink_to(aside) if damage == "link" else __import__("os").mkfifo(kept)
    else:  # another morphology's entry under this name: its key does not check
        other = "0" * 64
        kept.write_bytes(disk.encode(other, clips))
    creature, physics = _creature()
    key = disk.entry_key(recording_input(creature, physics), QUICK)
    layout = _morphology(creature, physics)
    shape = disk.Shape(list(layout.bodies), clips.idle.qpos.shape[1], clips.idle.qvel.shape[1],
                       clips.idle.dt)  # fmt: skip
    assert disk.read(key, shape, layout.key) is None
    again = _read_again()  # recorded again, and kept in place of the bad entry
    assert again.crawl.speed == clips.crawl.speed
    if damage != "fifo":
        assert disk.read(key, shape, layout.key) is not None


def test_a_forged_entry_must_fit_the_creature(recorded: tuple[GaitClips, pathlib.Path]) -> None:
    """The digests are no secret: an entry written with them still has to hold clips
    of the creature's shape, finite, unit rotations, bodies near the origin."""
    clips, kept = recorded
    key = kept.stem
    creature, physics = _creature()
    layout = _morphology(creature, physics)
    nq, nv = clips.idle.qpos.shape[1], clips.idle.qvel.shape[1]
    shape = disk.Shape(list(layout.bodies), nq, nv, clips.idle.dt)
    assert disk.read(key, shape, layout.key) is not None
    for wrong in (
        disk.Shape(list(layout.bodies)[:-1], nq, nv, clips.idle.dt),  # another body plan
        disk.Shape(list(layout.bodies), nq + 1, nv + 1, clips.idle.dt),
        disk.Shape(list(layout.bodies), nq, nv, clips.idle.dt / 2),  # another frame rate
    ):
        assert disk.read(key, wrong, layout.key) is None
    for forge in ("nan", "quat", "far"):
        bad = GaitClips(clips.key, clips.bodies, clips.idle, clips.crawl, clips.seconds,
                        clips.store_lag)  # fmt: skip
        bad.crawl = type(clips.crawl)(**{**vars(clips.crawl), "pos": clips.crawl.pos.copy(),
                                         "quat": clips.crawl.quat.copy()})  # fmt: skip
        if forge == "nan":
            bad.crawl.pos[3, 2, 1] = np.nan
        elif forge == "quat":
            bad.crawl.quat[3, 2] *= 1.5
        else:
            bad.crawl.pos[3, 2, 0] = 5000.0
        kept.write_bytes(disk.encode(key, bad))
        assert disk.read(key, shape, layout.key) is None


def test_the_key_changes_with_what_is_recorded() -> None:
    creature, physics = _creature()
    recording = recording_input(creature, physics)
    faster = recording_input({**creature, "locomotion": {"speed": 1.6}}, physics)
    keys = {
        disk.entry_key(recording, QUICK),
        disk.entry_key(faster, QUICK),
        disk.entry_key(recording, {**QUICK, "seconds": 3.0}),
    }
    assert len(keys) == 3
    assert disk.entry_key(recording, dict(QUICK)) in keys  # the same inputs, the same key
