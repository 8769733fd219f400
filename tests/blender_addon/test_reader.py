"""The add-on's own take reader (numpy and the standard library: Blender's Python runs
it) reads what the project writes, and refuses a broken take in one line naming the
file, before it allocates what the file claims."""

from __future__ import annotations

import json
import re
import zipfile
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from ecs_tentacles.blender_addon import reader
from ecs_tentacles.blender_addon.ground import meshes as ground_meshes
from ecs_tentacles.blender_addon.motion import Plan
from ecs_tentacles.blender_addon.reader import TakeFile, TakeFileError
from ecs_tentacles.blender_addon.stream import Group, kinds, plans_of, read_motion, replay_arrays
from ecs_tentacles.take import Take
from ecs_tentacles.take.chunks import add_entry, npy_bytes
from ecs_tentacles.take.stream import open_take
from tests.conftest import baked
from tests.export.broken_takes import BROKEN_TAKES

# the cases that break what the add-on reads: the header's timing, creatures and bodies,
# the poses, the roster, the archive itself (it reads no goal, sucker or guide)
REFUSED = [
    "nan_position", "inf_quaternion", "zero_quaternion", "quat_int32", "pos_big_endian",
    "pos_float64", "pos_one_frame_more", "quat_three_numbers", "missing_quat", "object_array",
    "npy_data_cut_short", "fps_zero", "fps_huge_negative", "fps_huge", "position_far_out",
    "fps_string", "fps_nan", "frames_zero", "frames_float", "frames_billions",
    "frames_trillion_without_bodies", "version_3", "no_format", "header_not_json",
    "body_index_out_of_range", "creature_without_tentacles", "tentacle_without_links",
    "body_used_twice", "creature_name_trailing_newline", "creature_name_slash",
    "body_radius_nan", "bodies_not_a_list", "roster_without_visible_array",
    "roster_visible_one_frame_short", "roster_visible_as_numbers", "zip_bomb_directory",
    "truncated_file", "empty_file", "not_a_zip",
]  # fmt: skip
V1_TAKE = Path(__file__).resolve().parents[1] / "data" / "octopus_take_v1.npz"
V2_TAKE = V1_TAKE.with_name("octopus_take_v2.npz")


@pytest.fixture(scope="module")
def good_take(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """thesis_four_by_six, 0.3 s at 30 fps: four creatures of one body plan."""
    return baked("thesis_four_by_six", tmp_path_factory.mktemp("good") / "four.npz", 0.3)


def read_everything(path: Path) -> np.ndarray:
    """What an import reads of the take at `path`: the header, the replay, the body
    poses turned into keys (`stream.read_motion`), the roster; the root motion."""
    with TakeFile(path) as take:
        replay = replay_arrays(take)
        kind = kinds(take, replay)
        groups = [Group(plan, members, np.tile([1.0, 0, 0, 0], (plan.joints, 1)))
                  for plan, members in plans_of(take).items()]  # fmt: skip
        root = read_motion(take, groups, kind, replay, lambda fraction, text: None)
        if take.roster:
            take.per_frame("creature_visible")
        return root


def test_a_version_1_take_reads_as_the_project_reads_it_a_block_at_a_time(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    expected = Take.load(V1_TAKE)
    row = expected.pos[0].nbytes + expected.quat[0].nbytes
    monkeypatch.setattr(reader, "BLOCK_BYTES", 3 * row)  # blocks of three frames
    with TakeFile(V1_TAKE) as take:
        assert take.version == 1
        assert (take.frames, take.fps) == (expected.frames, expected.fps)
        firsts, pos, quat = [], [], []
        for first, block in take.blocks(("pos", "quat")):
            firsts.append(first)
            pos.append(block["pos"])
            quat.append(block["quat"])
    assert firsts == list(range(0, expected.frames, 3))
    np.testing.assert_array_equal(np.concatenate(pos), expected.pos)
    np.testing.assert_array_equal(np.concatenate(quat), expected.quat)


def test_a_version_2_take_reads_with_its_bodies_listed() -> None:
    expected = Take.load(V2_TAKE)
    with TakeFile(V2_TAKE) as take:
        assert (take.version, take.frames, take.bodies) == (2, expected.frames, 81)
        pos = np.concatenate([b["pos"] for _, b in take.blocks(("pos",))])
        np.testing.assert_array_equal(pos, expected.pos)


def test_a_version_3_take_reads_as_the_project_reads_it_a_chunk_at_a_time(
    good_take: Path,
) -> None:
    expected = Take.load(good_take)
    with TakeFile(good_take) as take:
        assert (take.version, take.frames, take.fps) == (3, expected.frames, expected.fps)
        assert [c.name for c in take.creatures] == [c["name"] for c in expected.header["creatures"]]
        pos = np.concatenate([b["pos"] for _, b in take.blocks(("pos",))])
        np.testing.assert_array_equal(pos, expected.pos)
        mantle = expected.header["creatures"][1]["mantle"]
        assert take.creatures[1].bodies[0] == mantle
        (plan,) = plans_of(take)  # four creatures of one body plan
        assert isinstance(plan, Plan) and plan.joints == len(take.creatures[1].bodies)
    root = read_everything(good_take)
    np.testing.assert_allclose(root[:, 1, :2], expected.pos[:, mantle, :2], atol=1e-6)


@pytest.mark.parametrize("case", REFUSED)
def test_a_broken_take_is_refused_in_one_line_naming_the_file(
    case: str, good_take: Path, tmp_path: Path
) -> None:
    bad = tmp_path / f"{case}.npz"
    BROKEN_TAKES[case](good_take, bad)
    with pytest.raises(TakeFileError) as refused:
        read_everything(bad)
    message = str(refused.value)
    assert "\n" not in message and message.startswith(f"{bad}: "), message
    assert len(message) < 300, message


def test_a_missing_file_and_a_folder_are_one_line_each(tmp_path: Path) -> None:
    for path, said in ((tmp_path / "none.npz", "no such file"), (tmp_path, "not a regular file")):
        with pytest.raises(TakeFileError, match=f"^{path}: {said}$"):
            TakeFile(path)


@pytest.mark.parametrize(
    ("ground", "said"),
    [
        ({"digest": "x", "meshes": []}, "header.ground.meshes: must list 1 to 8 meshes"),
        ({"digest": "x", "meshes": [{"name": "a b", "vertices": 3, "triangles": 1}]},
         "header.ground.meshes[0].name: must be a unique identifier, got 'a b'"),
        ({"digest": "x", "meshes": [{"name": "t", "vertices": 0, "triangles": 1}]},
         "header.ground.meshes[0]: vertices and triangles must be whole numbers >= 1"),
        ({"digest": "x", "meshes": [{"name": "t", "vertices": 3, "triangles": 1,
                                     "rgb": [2, 0, 0]}]},
         "header.ground.meshes[0].rgb: must be three numbers in [0, 1]"),
    ],
)  # fmt: skip
def test_a_broken_ground_entry_is_one_line(ground: dict[str, object], said: str) -> None:
    with pytest.raises(TakeFileError, match=f"^{re.escape(said)}$"):
        ground_meshes({"ground": ground})


def _rewrite(good: Path, bad: Path, change: Any) -> None:
    """`bad`: `good`'s entries (name -> array) as `change(header, entries)` leaves them."""
    with zipfile.ZipFile(good) as archive:
        entries = {
            i.filename.removesuffix(".npy"): np.lib.format.read_array(archive.open(i))
            for i in archive.infolist()
        }
    header = json.loads(entries["header"].tobytes())
    change(header, entries)
    entries["header"] = np.frombuffer(json.dumps(header).encode(), np.uint8)
    with zipfile.ZipFile(bad, "w") as archive:
        for name, array in entries.items():
            add_entry(archive, f"{name}.npy", npy_bytes(array))


def _flip_in_pos(good: Path, bad: Path) -> None:
    """A byte of the first pose chunk's compressed data flipped (its CRC no longer holds)."""
    with zipfile.ZipFile(good) as archive:
        entry = archive.getinfo("pos.000000.npy")
    data = bytearray(good.read_bytes())
    at = entry.header_offset + 30 + len(entry.filename) + entry.compress_size // 2
    data[at] ^= 0xFF
    bad.write_bytes(bytes(data))


def _drop(name: str) -> Any:
    return lambda good, bad: _rewrite(good, bad, lambda h, e: e.pop(name))


VERSION_2_CASES = {
    "corrupt_pose_chunk": (_flip_in_pos, "pos chunk 0: cannot be read (Bad CRC-32"),
    "missing_chunk": (_drop("quat.000000"), "quat chunk 0: missing (quat.000000.npy)"),
    "chunks_longer_than_said": (
        lambda good, bad: _rewrite(good, bad, lambda h, e: h.update(chunk_frames=4)),
        "replay_kind chunk 0: dtype int8 shape (10, 4), expected int8 (4, 0..4)",
    ),
    "replayed_without_a_clip": (
        lambda good, bad: _rewrite(
            good, bad, lambda h, e: e["replay_kind.000000"].__setitem__((2, 1), 1)
        ),
        "replay_kind: 1 at frame 2, creature 1: must be -1, or 0 or 1 for a creature with a clip",
    ),
    "no_chunked_list_of_poses": (
        lambda good, bad: _rewrite(good, bad, lambda h, e: h.update(chunked=["quat"])),
        "header.chunked: must hold pos and quat",
    ),
}


@pytest.mark.parametrize("case", sorted(VERSION_2_CASES))
def test_a_broken_version_2_take_is_refused_in_one_line(
    case: str, good_take: Path, tmp_path: Path
) -> None:
    make, said = VERSION_2_CASES[case]
    bad = tmp_path / f"{case}.npz"
    make(good_take, bad)
    with pytest.raises(TakeFileError) as refused:
        read_everything(bad)
    assert str(refused.value).startswith(f"{bad}: {said}"), str(refused.value)


def test_a_creature_missing_from_early_chunks_reads_as_the_project_reads_it(
    good_take: Path, tmp_path: Path
) -> None:
    """A creature spawned while a bake streamed its take is missing from the chunks
    written before it came (its bodies last): both readers give it its values at the
    first frame of the first chunk holding everyone."""
    late = tmp_path / "late.npz"

    def rechunk(header: dict[str, Any], entries: dict[str, np.ndarray]) -> None:
        header["chunk_frames"] = 4
        last = header["creatures"][-1]
        bodies = min([last["mantle"], *(i for chain in last["tentacles"] for i in chain)])
        for name in header["chunked"]:
            whole = entries.pop(f"{name}.000000")
            for k, first in enumerate(range(0, len(whole), 4)):
                part = whole[first : first + 4]
                if k == 0 and name in ("pos", "quat"):
                    part = part[:, :bodies]
                elif k == 0 and name.startswith("replay_"):
                    part = part[:, :-1]
                entries[f"{name}.{k:06d}"] = np.ascontiguousarray(part)

    _rewrite(good_take, late, rechunk)
    with open_take(late) as source:
        expected = np.concatenate([chunk.pos for _, chunk in source.chunks()])
    with TakeFile(late) as take:
        assert take.chunk_frames == 4
        pos = np.concatenate([b["pos"] for _, b in take.blocks(("pos",))])
    np.testing.assert_array_equal(pos, expected)
    original = Take.load(good_take).pos
    assert not np.array_equal(pos[:4], original[:4])  # the late creature at frame 4's place
    np.testing.assert_array_equal(pos[4:], original[4:])
