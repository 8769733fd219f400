"""Recording a frame (`export.recording.TakeRecorder.capture`, the record system's work) is
whole-array work: the Python calls it makes do not grow with the creatures, their bodies,
suckers, goals or fur guides, before or after creatures came and went."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ecs_tentacles.creator.crowd import crowd_scene
from ecs_tentacles.export.recording import TakeRecorder
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


def test_a_recorded_frame_makes_the_same_python_calls_whatever_the_crowd(
    make_world: Callable[..., World],
) -> None:
    calls = {}
    for creatures in (2, 8):
        world, recorder = _recording(make_world, creatures)
        steady = python_calls(recorder.capture)
        world.despawn(world.creature("c0"))  # the recorder gathers around the hole now
        world.step()  # recorded: the guides' owners changed, mapped once
        world.step()
        changed = python_calls(recorder.capture)
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
