"""Bare frames (the bench's MuJoCo alone) step the framework's very inputs: same results."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from ecs_tentacles.creator.crowd import crowd_scene
from ecs_tentacles.physics.bare import BareFrame, FrameCapture
from ecs_tentacles.physics.tiers import FULL, REDUCED
from ecs_tentacles.world import World


def _captured_then_stepped(world: World) -> tuple[BareFrame, list[np.ndarray], list[np.ndarray]]:
    """Capture the next frame's inputs, run the frame; the frame and every batch's full
    and reduced state rows after it."""
    physics = world.physics
    capture = FrameCapture(physics, keep=True)
    world.step(1)
    capture.close()
    (frame,) = capture.frames
    batches = physics.batches
    rstates = [b.rstate[np.maximum(b.rslot, 0)] if len(b.rstate) else b.rstate for b in batches]
    return frame, [b.state.copy() for b in batches], rstates  # (by row: rows holding one)


@pytest.mark.parametrize("threads", [1, 2])
def test_a_bare_frame_ends_where_the_framework_frame_ended(
    make_world: Callable[..., World], threads: int
) -> None:
    scene = crowd_scene(4, seed=3, spacing=4.0, uniform=True)  # nobody near anybody
    focus = {"center": [0.0, 0.0], "radius": 0.0}  # the two nearest it run full
    scene["physics"] = {"lod": {"full": 2, "reduced": 2, "hold_seconds": 0, "focus": focus}}
    world = make_world(scene, threads=threads)
    world.step(8)  # two demoted to REDUCED
    frame, states, rstates = _captured_then_stepped(world)
    assert {FULL, REDUCED} <= set(frame.rows[0])
    before = {tier: r.states.copy() for tier, r in frame.rows[0].items()}
    for _ in range(2):  # a captured frame can be stepped again: its inputs stay
        world.physics.step_bare(frame, world.settings.substeps)
        full, reduced = frame.rows[0][FULL], frame.rows[0][REDUCED]
        np.testing.assert_array_equal(full.after, states[0][full.rows])
        np.testing.assert_array_equal(reduced.after, rstates[0][reduced.rows])
        for tier, rows in frame.rows[0].items():
            np.testing.assert_array_equal(rows.states, before[tier])


def test_a_pushed_creature_is_pushed_in_the_bare_frame_too(
    make_world: Callable[..., World],
) -> None:
    world = make_world(crowd_scene(3, seed=2, spacing=4.0, uniform=True), lod=False)
    world.step(2)
    view = world.physics.views[1]
    view.data.xfrc_applied[view.body_ids[0], 2] = 50.0  # a script pushes its mantle up
    frame, states, _ = _captured_then_stepped(world)
    full = frame.rows[0][FULL]
    assert list(full.forces) == [1]  # creature 1's row, by its position among the rows
    world.physics.step_bare(frame, world.settings.substeps)
    np.testing.assert_array_equal(full.after, states[0][full.rows])


def test_bare_frames_leave_the_world_alone(make_world: Callable[..., World]) -> None:
    scene = crowd_scene(2, seed=1, uniform=True)
    measured, plain = make_world(scene), make_world(scene)
    frame, _, _ = _captured_then_stepped(measured)
    state = measured.physics.state()
    measured.physics.step_bare(frame, measured.settings.substeps)
    after = measured.physics.state()
    for a, b in zip(
        [s.states for s in state.batches], [s.states for s in after.batches], strict=True
    ):
        np.testing.assert_array_equal(a, b)
    plain.step(1)
    measured.step(3)
    plain.step(3)
    np.testing.assert_array_equal(measured.transforms.pos, plain.transforms.pos)
