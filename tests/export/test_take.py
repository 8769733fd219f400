"""Takes: recording equals the live world, the file round-trips, bakes are reproducible."""

from __future__ import annotations

import json
import zipfile
from pathlib import Path

import numpy as np
import pytest

from ecs_tentacles.components import Creature, Sucker, Tentacle, Transform
from ecs_tentacles.export.bake import BakePlan, bake, simulation_rate
from ecs_tentacles.locomotion.goals import GoalBook
from ecs_tentacles.options import WorldOptions
from ecs_tentacles.record.systems.record import Record
from ecs_tentacles.take import ARRAYS, Take, TakeError
from ecs_tentacles.world import World
from tests.export.conftest import LINK_CENTRES, SMALL_SCENE, link_centres


def live_poses(world: World) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Every body's pose by its take name, read through components (not the recorder)."""
    poses = {}
    for entity, creature in world.query(Creature):
        mantle = world.component(entity, Transform)
        poses[f"{creature.name}/mantle"] = (mantle.pos.copy(), mantle.quat.copy())
        for tentacle_entity in creature.tentacles:
            tentacle = world.component(tentacle_entity, Tentacle)
            for i, link in enumerate(tentacle.links):
                t = world.component(link, Transform)
                name = f"{creature.name}/tentacles/t{tentacle.index}/link{i}"
                poses[name] = (t.pos.copy(), t.quat.copy())
    return poses


def test_take_round_trip_equals_the_live_world_at_sampled_frames(tmp_path: Path) -> None:
    world = World.from_scene(SMALL_SCENE)
    system = Record(2, tracks=[LINK_CENTRES])
    world.add_system(system)
    live = {0: live_poses(world)}
    attached = {0: world.suckers.attached.copy()}
    for frame in range(1, 7):  # take frames 1..6 are world frames 2, 4, ... 12
        world.step(2)
        live[frame] = live_poses(world)
        attached[frame] = world.suckers.attached.copy()
    guides_now = link_centres(world)
    system.take().save(tmp_path / "take.npz")
    take = Take.load(tmp_path / "take.npz")
    assert (take.frames, take.fps, take.header["sim_fps"], take.header["seed"]) == (
        7,
        30.0,
        60.0,
        4,
    )
    assert len(take.body_names) == 1 + 3 * 4 and take.body_names[0] == "octo/mantle"
    np.testing.assert_array_equal(take.times, np.arange(7) / 30.0)
    for frame in (0, 3, 6):
        for name, (pos, quat) in live[frame].items():
            index = take.body(name)
            np.testing.assert_array_equal(take.pos[frame, index], pos.astype(np.float32))
            np.testing.assert_array_equal(take.quat[frame, index], quat.astype(np.float32))
        np.testing.assert_array_equal(take.sucker_attached[frame], attached[frame])
    # curves' points are stored in steps of 0.1 mm: at most 0.05 mm off (and float32)
    np.testing.assert_allclose(
        take.tracks["guide_points"][6], guides_now.points.astype(np.float32), atol=5.01e-5, rtol=0
    )
    assert take.header["guides"] == {"creatures": [0, 0, 0]}
    tips = [world.component(e, Sucker) for e in world.suckers.entity]
    assert [s["name"] for s in take.header["suckers"]] == [
        f"octo/tentacles/t{k}/link3/sucker0" for k in range(3)
    ]
    assert [s["offset"] for s in take.header["suckers"]] == [t.offset.tolist() for t in tips]
    world.close()


def test_goals_added_and_removed_while_recording_are_tracked() -> None:
    world = World.from_scene(SMALL_SCENE)
    system = Record()
    world.add_system(system)
    octo = world.creature("octo")
    world.step(1)
    extra = world.resource(GoalBook).append(octo, [0.0, 2.0], 0.5)
    world.step(1)
    world.resource(GoalBook).remove(extra)
    world.step(1)
    take = system.take()
    assert take.header["goals"] == [
        {"name": "octo/goals/goal0", "creature": 0, "radius": 0.2},
        {"name": "octo/goals/goal1", "creature": 0, "radius": 0.5},
    ]
    np.testing.assert_array_equal(take.tracks["goal_pos"], [[1.0, 0.0, 0.0], [0.0, 2.0, 0.0]])
    np.testing.assert_array_equal(take.tracks["goal_active"], [[1, 0], [1, 0], [1, 1], [1, 0]])
    world.close()


def test_two_bakes_of_the_same_scene_and_seed_are_byte_identical(tmp_path: Path) -> None:
    plan = BakePlan.make(SMALL_SCENE, seconds=0.25, fps=30)
    bake(plan, progress=False).save(tmp_path / "a.npz")
    bake(plan, progress=False).save(tmp_path / "b.npz")
    other = BakePlan.make(SMALL_SCENE, WorldOptions(seed=5), seconds=0.25, fps=30)
    bake(other, progress=False).save(tmp_path / "c.npz")
    a, b, c = ((tmp_path / f"{n}.npz").read_bytes() for n in "abc")
    assert a == b
    assert a != c  # the seed matters (per-tentacle wave phases)
    with zipfile.ZipFile(tmp_path / "a.npz") as archive:
        entries = archive.infolist()
    replay = ["replay_kind", "replay_phase", "replay_xy", "replay_heading"]
    chunked = [f"{n}.000000.npy" for n in [*ARRAYS[1:5], *replay]]  # one chunk of 9 frames
    assert [e.filename for e in entries] == [*chunked, "goal_pos.npy", "goal_active.npy",
                                             "header.npy"]  # fmt: skip
    assert {e.date_time for e in entries} == {(1980, 1, 1, 0, 0, 0)}
    header = json.loads(np.load(tmp_path / "a.npz")["header"].tobytes())
    assert header["scene_sha256"] == plan.scene_sha256 and len(plan.scene_sha256) == 64
    assert (header["frames"], header["fps"], header["seed"]) == (9, 30.0, 4)


@pytest.mark.parametrize(
    ("scene_fps", "take_fps", "substeps", "expected"),
    [
        (60, 60, 8, (1, 60, 8)),
        (60, 30, 8, (2, 60, 8)),
        (60, 24, 8, (2, 48, 10)),  # 1/480 s steps as in `run`, every other frame kept
        (60, 120, 8, (1, 120, 4)),
        (60, 240, 8, (1, 240, 2)),
        (50, 30, 8, (2, 60, 8)),  # no multiple of 30 is a whole number of 1/400 s steps
        (60, 25, 8, (3, 75, 8)),
        (30, 24, 16, (1, 24, 20)),
        (4, 1000, 100, (1, 1000, 100)),  # 0.4 steps a frame: the scene's substeps, shorter
    ],
)
def test_simulation_rate(
    scene_fps: float, take_fps: float, substeps: int, expected: tuple[int, float, int]
) -> None:
    every, sim_fps, sim_substeps = simulation_rate(scene_fps, take_fps, substeps)
    assert (every, sim_fps, sim_substeps) == expected
    assert sim_fps == pytest.approx(take_fps * every)  # every take frame is a simulated one
    if sim_substeps != substeps:  # the scene's physics step is kept exactly
        assert sim_fps * sim_substeps == pytest.approx(scene_fps * substeps)


def test_a_24_fps_take_simulates_at_48_fps_with_the_scenes_physics_step() -> None:
    plan = BakePlan.make(SMALL_SCENE, seconds=0.25, fps=24)
    assert (plan.every, plan.sim_fps, plan.substeps, plan.frames, plan.steps) == (
        2,
        48.0,
        10,
        7,
        12,
    )
    take = bake(plan, progress=False)
    assert (take.frames, take.fps, take.header["sim_fps"]) == (7, 24.0, 48.0)
    physics = SMALL_SCENE.get("physics", {})
    scene_step = 1 / (physics.get("fps", 60) * physics.get("substeps", 8))
    assert 1 / (take.header["sim_fps"] * take.header["substeps"]) == pytest.approx(scene_step)


def _take(tmp_path: Path, **changes: object) -> Path:
    world = World.from_scene(SMALL_SCENE)
    system = Record()
    world.add_system(system)
    take = system.take()
    world.close()
    # a version 1 file (one entry per array, no replay records)
    base = {k: v for k, v in take.header.items() if k != "replay"} | {"version": 1}
    arrays = {k: v for k, v in take.arrays().items() if not k.startswith("replay_")}
    arrays["header"] = np.frombuffer(json.dumps(base).encode(), np.uint8)
    for key, value in changes.items():
        if key == "header":
            header = {**base, **value}  # type: ignore[dict-item]
            arrays["header"] = np.frombuffer(json.dumps(header).encode(), np.uint8)
        elif value is None:
            del arrays[key]
        else:
            arrays[key] = value  # type: ignore[assignment]
    path = tmp_path / "t.npz"
    np.savez(path, **arrays)
    return path


def test_bad_take_files_give_one_line(tmp_path: Path) -> None:
    junk = tmp_path / "junk.npz"
    junk.write_text("hello")
    cases = {
        tmp_path / "missing.npz": "no such file",
        junk: "not a take file (not an npz archive)",
    }
    for path, message in cases.items():
        with pytest.raises(TakeError) as caught:
            Take.load(path)
        assert str(caught.value) == f"{path}: {message}"
    for changes, message in [
        ({"header": {"version": 9}}, "header.version: this reader knows versions 1 to 3, got 9"),
        ({"header": {"format": "x"}}, "header.format: expected 'ecs_tentacles.take'"),
        ({"quat": None}, "quat: missing"),
        (
            {"pos": np.zeros((2, 13, 3), np.float32)},
            "pos: shape (2, 13, 3), expected (1, 13, 3) from the header",
        ),
    ]:
        path = _take(tmp_path, **changes)
        with pytest.raises(TakeError) as caught:
            Take.load(path)
        assert str(caught.value) == f"{path}: {message}"


def _stretched(take: Take, frames: int, guides: int, points: int = 4) -> Take:
    """`take` as if it ran `frames` frames with `guides` guides: views of its first frame
    (nothing is allocated)."""
    header = {**take.header, "frames": frames, "guides": {"creatures": [0] * guides}}

    def each_frame(array: np.ndarray, shape: tuple[int, ...] | None = None) -> np.ndarray:
        return np.broadcast_to(array[:1], (frames, *(shape or array.shape[1:])))

    tracks = {**take.tracks, "goal_active": each_frame(take.tracks["goal_active"])}
    for name in [n for n in tracks if n.startswith("replay_") and not n.startswith("replay_clip")]:
        tracks[name] = each_frame(tracks[name])
    tracks["guide_points"] = each_frame(take.tracks["guide_points"][:, :1, :1], (guides, points, 3))
    tracks["guide_widths"] = each_frame(take.tracks["guide_widths"][:, :1, :1], (guides, points))
    return Take(
        header=header,
        pos=each_frame(take.pos),
        quat=each_frame(take.quat),
        sucker_attached=each_frame(take.sucker_attached),
        sucker_anchor=each_frame(take.sucker_anchor),
        tracks=tracks,
    )


def test_a_take_too_big_to_read_back_is_never_written(guided_take: Take, tmp_path: Path) -> None:
    """What a bake cannot count before it starts (tracks that grow while it runs, creatures
    spawned) may still make a take whose reader would decode over 2 GiB at once (the
    tracks held whole, a chunk of the rest): `save` refuses it in one line and writes
    nothing, as the reader would refuse it; just under the limit it is kept. A long shot
    alone is no reason: its frames are read a chunk at a time."""
    out = tmp_path / "take.npz"
    long_shot = _stretched(guided_take, 100_000, 330)  # 64 bytes a guide a frame: 2 GiB
    assert long_shot.size_problem() is None
    over = _stretched(guided_take, 2, 1_000_000, 135)  # one frame of guides: 2.16 GB
    with pytest.raises(TakeError) as refused:
        over.save(out)
    assert str(refused.value) == (
        f"{out}: cannot write this take: its 13 arrays would be 2,162,002,707 bytes to read at"
        " once, over the 2,147,483,648 (2 GiB) a take's reader decodes at once"
    )
    assert list(tmp_path.iterdir()) == []
    assert _stretched(guided_take, 2, 1_000_000, 133).size_problem() is None
