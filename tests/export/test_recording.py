"""Recording a frame (`export.recording.TakeRecorder.capture`, the record system's work) is
whole-array work: the Python calls it makes do not grow with the creatures, their bodies,
suckers, goals or fur guides, before or after creatures came and went."""

from __future__ import annotations

import gc
from collections.abc import Callable

import numpy as np
import pytest

from ecs_tentacles.creator.crowd import crowd_scene
from ecs_tentacles.export.recording import TakeRecorder, scene_sha256
from ecs_tentacles.record.plugin import RecordPlugin
from ecs_tentacles.world import World
from tests.conftest import python_calls

FUR = {"preset": "bird", "groom": {"count": 12, "seed": 5}}


def _recording(make_world: Callable[..., World], creatures: int) -> tuple[World, TakeRecorder]:
    """A uniform crowd, every creature furred and with a goal, recording from frame 0."""
    scene = crowd_scene(creatures, 3, uniform=True)
    for creature in scene["creatures"]:
        creature["fur"] = FUR
    world = make_world(scene)
    record = RecordPlugin()  # told of spawns and despawns, as in a bake
    world.add_plugin(record)  # records frame 0: every goal appears
    world.step()
    assert record.system.recorder is not None
    return world, record.system.recorder


def _calls(action: Callable[[], object]) -> int:
    """`python_calls(action)` with the cyclic garbage collector held off (a collection
    can run Python callbacks of whatever else the process holds)."""
    gc.collect()
    gc.disable()
    try:
        return python_calls(action)
    finally:
        gc.enable()


def test_a_recorded_frame_makes_the_same_python_calls_whatever_the_crowd(
    make_world: Callable[..., World],
) -> None:
    calls = {}
    for creatures in (2, 8):
        world, recorder = _recording(make_world, creatures)
        steady = _calls(recorder.capture)
        world.despawn(world.creature("c0"))  # the recorder gathers around the hole now
        world.step()  # recorded: the guides' owners changed, mapped once
        world.step()
        changed = _calls(recorder.capture)
        calls[creatures] = (steady, changed)
        take = recorder.take()
        assert take.frames == 6
        assert len(take.header["goals"]) == creatures
        visible = take.tracks["creature_visible"]
        assert visible[:, 0].tolist() == 3 * [True] + 3 * [False]
        assert visible[:, 1:].all()
        owners = take.header["guides"]["creatures"]
        assert sorted(set(owners)) == list(range(creatures))
        assert take.tracks["guide_points"].shape[:2] == (6, len(owners))
        assert np.isfinite(take.tracks["guide_points"]).all()
    assert calls[2] == calls[8], calls  # array work: no Python per creature, goal or guide


def test_finishing_hands_the_frames_over_and_the_world_steps_on(
    make_world: Callable[..., World],
) -> None:
    world = make_world(crowd_scene(2, 3, uniform=True))
    record = RecordPlugin()
    world.add_plugin(record)
    world.step(3)
    kept = record.take()  # a copy: recording goes on
    assert not np.shares_memory(kept.pos, record.system.recorder.take().pos)
    take = record.finish()  # the recorder's own arrays: a bake holds its frames once
    recorder = record.system.recorder
    assert recorder is not None and recorder.finished
    assert np.shares_memory(take.pos, record.finish().pos) and take.frames == 4
    assert take.header["frames"] == 4
    np.testing.assert_array_equal(take.pos, kept.pos)
    assert take.header == kept.header
    world.spawn({"name": "late", "tentacles": {"count": 3}}, position=[9.0, 9.0])
    world.step(2)  # the record system records no more, the take stays as it was
    assert take.frames == 4 and recorder.count == 4
    assert take.header == kept.header and len(take.header["creatures"]) == 2
    with pytest.raises(RuntimeError, match="finished"):
        recorder.capture()


def test_a_scene_hashes_the_same_whichever_key_names_the_clips_plugin() -> None:
    # a take's `scene_sha256` reads plugins by the keys they had first: a scene that
    # names the clips plugin by its key now hashes as it did under its former key, `lod`
    # (so takes, and shards of a distributed bake, keep their hashes across the rename)
    now = {"version": 1, "plugins": {"clips": {}, "wander": {"radius": 1.0}}}
    before = {"version": 1, "plugins": {"lod": {}, "wander": {"radius": 1.0}}}
    assert scene_sha256(now) == scene_sha256(before)
    assert scene_sha256(now) != scene_sha256({**now, "plugins": {"clips": False}})
    assert now["plugins"] == {"clips": {}, "wander": {"radius": 1.0}}  # left as it was
