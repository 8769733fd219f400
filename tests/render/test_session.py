"""The sandbox's simulation without a window (`render.session`): the clock's frames,
a rebuild, a reset that cannot build, a saved state."""

from __future__ import annotations

import copy

import numpy as np
import pytest

from ecs_tentacles.render.session import MAX_CATCH_UP, SandboxSession


def test_the_clock_gives_whole_frames_and_catches_up_at_most_a_quarter_second() -> None:
    said: list[tuple[bool, str]] = []
    session = SandboxSession("octopus", say=lambda ok, text: said.append((ok, text)))
    try:
        dt = session.world.settings.dt
        assert session.due(2.5 * dt) == 2 and session.accumulator == pytest.approx(0.5 * dt)
        assert session.due(10.0) == int((MAX_CATCH_UP + 1e-9) // dt)  # not 10 s of frames
        session.paused = True
        assert session.due(1.0) == 0
    finally:
        session.world.close()


def test_rebuild_reset_and_saved_state() -> None:
    said: list[tuple[bool, str]] = []
    session = SandboxSession("octopus", say=lambda ok, text: said.append((ok, text)))
    try:
        scene = copy.deepcopy(session.world.scene)
        assert scene is not None
        session.world.step(10)
        session.save_state()
        start = session.world.transforms.pos.copy()
        session.world.step(10)
        assert session.load_state()
        np.testing.assert_array_equal(session.world.transforms.pos, start)
        scene["creatures"][0]["name"] = "renamed"
        old = session.world
        rebuilt = session.rebuild(scene)
        assert rebuilt is session.world is not old and session.saved_state is None
        assert rebuilt.creature("renamed")
        session.scene = {**scene, "creatures": [{"mantle": {"radius": -1}}]}  # cannot build
        assert session.reset() is None and session.world is rebuilt
        assert said and said[-1][0] is False and said[-1][1].startswith("not reset: ")
    finally:
        session.world.close()
