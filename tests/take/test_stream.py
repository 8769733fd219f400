"""Version 2 takes: written as a bake goes, replayed creatures as clips, read a chunk at
a time; version 1 takes still read and export."""

from __future__ import annotations

import json
import shutil
import zipfile
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from ecs_tentacles.cli import main
from ecs_tentacles.export.bake import BakePlan, bake_to_file
from ecs_tentacles.take import VERSION, Take, TakeError, compact
from ecs_tentacles.take.stream import open_take

DATA = Path(__file__).parent.parent / "data"
MM = 1e-3


@pytest.fixture(scope="module")
def streamed(
    crowd_plan: BakePlan, tmp_path_factory: pytest.TempPathFactory
) -> tuple[Path, dict[str, Any] | None]:
    """The crowd baked to a file as it goes, once for the tests that only read it: the
    file and the header the bake returned."""
    out = tmp_path_factory.mktemp("streamed") / "streamed.npz"
    return out, bake_to_file(crowd_plan, out, progress=False)


def test_a_streamed_bake_holds_the_poses_the_world_showed(
    streamed: tuple[Path, dict[str, Any] | None], crowd_take: Take, tmp_path: Path
) -> None:
    out, header = streamed
    assert header is not None and header["frames"] == crowd_take.frames == 25
    replay = header["replay"]
    assert len(replay["clips"]) == 1 and sum(c >= 0 for c in replay["creatures"]) >= 5
    read = Take.load(out)
    kind = read.tracks["replay_kind"]
    assert (kind >= 0).sum() >= 5 * 20, "most creature-frames are replayed"
    # every pose as the world showed it (replayed ones rebuilt from their clip): lossless
    # for bodies stored, within the recorder's 1 mm check for replayed ones
    np.testing.assert_allclose(read.pos, crowd_take.pos, atol=MM, rtol=0)
    np.testing.assert_allclose(np.abs(np.sum(read.quat * crowd_take.quat, -1)), 1.0, atol=1e-5)
    physical = np.repeat(kind < 0, [1 + sum(map(len, c["tentacles"])) for c in
                                    read.header["creatures"]], axis=1)  # fmt: skip
    assert np.array_equal(read.pos[physical], crowd_take.pos[physical])
    # the fur's guide curves: stored in steps of 0.1 mm, at most 0.05 mm off
    np.testing.assert_allclose(
        read.tracks["guide_points"], crowd_take.tracks["guide_points"], atol=5.01e-5, rtol=0
    )
    # the in-memory take saved whole reads back the same
    crowd_take.save(tmp_path / "whole.npz")
    whole = Take.load(tmp_path / "whole.npz")
    assert np.array_equal(whole.pos, read.pos) and np.array_equal(whole.quat, read.quat)
    assert np.array_equal(whole.sucker_anchor, read.sucker_anchor)


def test_replayed_creatures_are_stored_as_clips_not_poses(
    streamed: tuple[Path, dict[str, Any] | None],
) -> None:
    out, _ = streamed
    with np.load(out) as raw:  # a plain npz: the documented few lines read it
        kind = raw["replay_kind.000000"]
        pos = raw["pos.000000"]
        clip = raw["replay_clip_0"]
    bodies = pos.shape[1] // 6
    replayed = np.repeat(kind >= 0, bodies, axis=1)
    assert not pos[replayed].any(), "a replayed creature's bodies are not stored"
    assert clip.shape[1:] == (bodies, 7)
    with open_take(out) as source:
        segments = source.segments(3)
        assert segments and segments[0].kind == 1  # crawling
        assert segments[-1].end == source.frames
        assert all(s.rate == pytest.approx(2.0) for s in segments)  # 48 fps clip, 24 fps take


def test_chunks_read_one_at_a_time_equal_the_whole(crowd_take: Take, tmp_path: Path) -> None:
    out = tmp_path / "take.npz"
    crowd_take.save(out)
    whole = Take.load(out)
    seen = 0
    with open_take(out) as source:
        for first, chunk in source.chunks(frames=7):
            assert first == seen and chunk.frames == min(7, whole.frames - first)
            assert np.array_equal(chunk.pos, whole.pos[first : first + 7])
            assert np.array_equal(
                chunk.tracks["goal_active"], whole.tracks["goal_active"][first : first + 7]
            )
            seen += chunk.frames
    assert seen == whole.frames


@pytest.mark.parametrize("version", [1, 2])
def test_an_old_take_reads_exports_and_migrates(version: int, tmp_path: Path) -> None:
    """A take written by an older writer (bundled: version 1, every array whole; version
    2, bodies listed one by one in the header) reads, exports, and saved again becomes a
    file of today's version holding the same frames, its bodies stored per body plan."""
    old = tmp_path / "old.npz"
    shutil.copy(DATA / f"octopus_take_v{version}.npz", old)
    take = Take.load(old)
    assert take.header["version"] == version and take.frames == 9
    assert main(["export", str(old), "--out", str(tmp_path / "old.usda"), "--quiet"]) == 0
    take.save(tmp_path / "new.npz")
    new = Take.load(tmp_path / "new.npz")
    assert new.header["version"] == VERSION == 3
    assert new.header["bodies"] == take.header["bodies"]
    assert new.header["suckers"] == take.header["suckers"]
    with np.load(tmp_path / "new.npz") as stored:
        assert compact.KEY in json.loads(bytes(stored["header"]))
    assert np.array_equal(new.pos, take.pos) and np.array_equal(new.quat, take.quat)
    assert np.array_equal(new.tracks["goal_active"], take.tracks["goal_active"])
    with open_take(old) as source:
        assert [f for f, _ in source.chunks(frames=4)] == [0, 4, 8]


def _rewrite(source: Path, target: Path, change) -> None:  # type: ignore[no-untyped-def]
    with zipfile.ZipFile(source) as src, zipfile.ZipFile(target, "w") as dst:
        for info in src.infolist():
            data = change(info.filename, src.read(info))
            if data is not None:
                dst.writestr(info, data)


def _npy(array: np.ndarray) -> bytes:
    import io

    buffer = io.BytesIO()
    np.lib.format.write_array(buffer, array)
    return buffer.getvalue()


def _header_edit(data: bytes) -> bytes:
    """The header entry `data` with every creature's clip taken away."""
    import io
    import json

    header = json.loads(np.load(io.BytesIO(data)).tobytes())
    header["replay"]["creatures"] = [-1] * len(header["creatures"])
    return _npy(np.frombuffer(json.dumps(header).encode(), np.uint8))


def test_a_take_that_lies_about_its_chunks_is_refused_in_one_line(
    crowd_take: Take, tmp_path: Path
) -> None:
    good = tmp_path / "good.npz"
    crowd_take.save(good)
    cases = {
        "a chunk missing": lambda n, d: None if n == "quat.000000.npy" else d,
        "a chunk of other frames": lambda n, d: _npy(np.zeros((3, 2, 3), np.float32))
        if n == "pos.000000.npy" else d,
        "a replay kind of 7": lambda n, d: _npy(np.full((25, 6), 7, np.int8))
        if n == "replay_kind.000000.npy" else d,
        "a replayed creature that has no clip": lambda n, d: _header_edit(d)
        if n == "header.npy" else d,
        "non-finite root motion": lambda n, d: _npy(np.full((25, 6), np.nan))
        if n == "replay_heading.000000.npy" else d,
    }  # fmt: skip
    expected = {
        "a chunk missing": "quat.000000: missing",
        "a chunk of other frames": "pos chunk 0: shape (3, 2, 3), expected (25, 0..",
        "a replay kind of 7": "replay_kind: must be -1, 0 or 1",
        "a replayed creature that has no clip": "replay_kind: a creature without a clip",
        "non-finite root motion": "replay_heading: values must be finite",
    }
    for name, change in cases.items():
        bad = tmp_path / f"{name.replace(' ', '_')}.npz"
        _rewrite(good, bad, change)
        with pytest.raises(TakeError) as refused:
            Take.load(bad)
        message = str(refused.value)
        assert "\n" not in message and str(bad) in message
        assert expected[name] in message, (name, message)
        with pytest.raises(TakeError):
            with open_take(bad) as source:
                for _ in source.chunks():
                    pass


def test_the_replay_check_decides_alike_with_and_without_its_kernel(
    crowd_plan: BakePlan,
    streamed: tuple[Path, dict[str, Any] | None],
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The recorder's one-pass check (numba) and the numpy reconstruction record the
    same replayed creature-frames: the two takes are byte for byte one file."""
    from ecs_tentacles.export import replay_recording

    pytest.importorskip("ecs_tentacles.export.replay_check_kernel")
    (fast, _), slow = streamed, tmp_path / "slow.npz"
    monkeypatch.setattr(replay_recording.KERNELS, "backend", "numpy")
    bake_to_file(crowd_plan, slow, progress=False)
    with open_take(fast) as source:
        assert any(source.segments(c) for c in range(len(source.header["creatures"])))
    assert fast.read_bytes() == slow.read_bytes()


def test_a_reader_that_asks_for_some_bodies_gets_those_posed_as_a_whole_read(
    streamed: tuple[Path, dict[str, Any] | None],
) -> None:
    out, _ = streamed
    with open_take(out) as source:
        full = [chunk for _, chunk in source.chunks()]
        header = source.header
        mantles = np.array([c["mantle"] for c in header["creatures"]])
        count = len(header["creatures"])
        whole = np.zeros((source.frames, count), dtype=bool)
        whole[3, :] = True  # frame 3: every creature posed whole
        some = [chunk for _, chunk in source.chunks(bodies=mantles, whole=whole)]
    pos = np.concatenate([c.pos for c in full])
    quat = np.concatenate([c.quat for c in full])
    kind = np.concatenate([c.tracks["replay_kind"] for c in full])
    part_pos = np.concatenate([c.pos for c in some])
    part_quat = np.concatenate([c.quat for c in some])
    owner = np.array([b["creature"] for b in header["bodies"]])
    replayed = kind[:, owner] >= 0  # (frames, bodies)
    asked = np.zeros(len(owner), dtype=bool)
    asked[mantles] = True
    posed = ~replayed | asked | whole[:, owner]
    assert (~posed).sum() > 1000, "most replayed bodies are left out"
    assert np.array_equal(part_pos[posed], pos[posed])  # the same bits where asked
    assert np.array_equal(part_quat[posed], quat[posed])
    assert not part_pos[~posed].any()  # the rest at the origin, unrotated: still sound
    assert np.array_equal(
        part_quat[~posed], np.broadcast_to([1, 0, 0, 0], (int((~posed).sum()), 4))
    )
