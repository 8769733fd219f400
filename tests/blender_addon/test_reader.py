"""The add-on's own take reader (numpy and the standard library: Blender's Python runs
it) reads what the project writes, and refuses a broken take in one line naming the
file, before it allocates what the file claims."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from ecs_tentacles.blender_addon import reader
from ecs_tentacles.blender_addon.ground import meshes as ground_meshes
from ecs_tentacles.blender_addon.motion import Plan
from ecs_tentacles.blender_addon.reader import TakeFile, TakeFileError
from ecs_tentacles.blender_addon.stream import Group, kinds, plans_of, read_motion, replay_arrays
from ecs_tentacles.cli import main
from ecs_tentacles.take import Take
from tests.export.broken_takes import BROKEN_TAKES

# the cases that break what the add-on reads: the header's timing, creatures and bodies,
# the poses, the roster, the archive itself (it reads no goal, sucker or guide)
REFUSED = [
    "nan_position", "inf_quaternion", "zero_quaternion", "quat_int32", "pos_big_endian",
    "pos_one_frame_more", "quat_three_numbers", "missing_quat", "object_array",
    "npy_data_cut_short", "fps_zero", "fps_huge_negative", "fps_huge", "position_far_out",
    "fps_string", "fps_nan", "frames_zero", "frames_float", "frames_billions",
    "frames_trillion_without_bodies", "version_2", "no_format", "header_not_json",
    "body_index_out_of_range", "creature_without_tentacles", "tentacle_without_links",
    "body_used_twice", "creature_name_trailing_newline", "creature_name_slash",
    "body_radius_nan", "bodies_not_a_list", "roster_without_visible_array",
    "roster_visible_one_frame_short", "roster_visible_as_numbers", "zip_bomb_directory",
    "corrupt_compressed_data", "truncated_file", "empty_file", "not_a_zip",
]  # fmt: skip


@pytest.fixture(scope="module")
def good_take(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """thesis_four_by_six, 0.3 s at 30 fps: four creatures of one body plan."""
    path = tmp_path_factory.mktemp("good") / "four.npz"
    argv = ["bake", "thesis_four_by_six", "--seconds", "0.3", "--fps", "30", "--quiet"]
    assert main([*argv, "--out", str(path)]) == 0
    return path


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


def test_a_take_reads_as_the_project_reads_it_a_block_at_a_time(
    good_take: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    expected = Take.load(good_take)
    row = expected.pos[0].nbytes + expected.quat[0].nbytes
    monkeypatch.setattr(reader, "BLOCK_BYTES", 3 * row)  # blocks of three frames
    with TakeFile(good_take) as take:
        assert (take.frames, take.fps) == (expected.frames, expected.fps)
        assert [c.name for c in take.creatures] == [c["name"] for c in expected.header["creatures"]]
        firsts, pos, quat = [], [], []
        for first, block in take.blocks(("pos", "quat")):
            firsts.append(first)
            pos.append(block["pos"])
            quat.append(block["quat"])
        assert firsts == list(range(0, expected.frames, 3))
        np.testing.assert_array_equal(np.concatenate(pos), expected.pos)
        np.testing.assert_array_equal(np.concatenate(quat), expected.quat)
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
