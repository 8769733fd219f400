"""The add-on's pose arithmetic (numpy only): a creature's replayed frames cut into
stretches of one clip at one rate, and a clip's poses between its frames."""

from __future__ import annotations

import numpy as np

from ecs_tentacles.blender_addon.motion import Segment, clip_poses, continuous, segments

FRAMES = (10, 20)  # idle, crawl


def test_one_kind_at_one_rate_is_one_stretch_even_where_the_phase_wraps() -> None:
    phase = (3.0 + 1.5 * np.arange(30)) % 20  # crawl, wrapping at 20 clip frames
    kind = np.ones(30, np.int8)
    assert segments(kind, phase, FRAMES, 1.5) == [Segment(0, 30, 1, 3.0, 1.5)]


def test_stretches_end_where_the_kind_or_the_rate_changes_or_the_creature_is_simulated() -> None:
    kind = np.array([-1, -1, 0, 0, 0, 1, 1, 1, 1, 1, -1, 0], np.int8)
    phase = np.array([0, 0, 2.0, 2.5, 3.0, 7.0, 8.0, 9.0, 11.0, 13.0, 0, 4.0]) + 40.0
    assert segments(kind, phase, FRAMES, 1.5) == [
        Segment(2, 5, 0, 2.0, 0.5),  # idle at half a clip frame a frame (42 mod 10 = 2)
        Segment(5, 8, 1, 7.0, 1.0),  # crawl at 1, then 2 a frame from frame 8 on
        Segment(8, 10, 1, 11.0, 2.0),
        Segment(11, 12, 0, 4.0, 1.5),  # a lone frame plays at the clip's own rate
    ]


def test_between_clip_frames_positions_are_linear_and_rotations_normalised() -> None:
    turn = np.pi / 2  # rows 0 and 1 turn by 90 degrees about z; row 1 stored as -q
    clip = np.zeros((2, 1, 7))
    clip[0, 0] = [0, 0, 0, 1, 0, 0, 0]
    clip[1, 0] = [2, 0, 0, -np.cos(turn / 2), 0, 0, -np.sin(turn / 2)]
    poses = clip_poses(clip, slice(0, 2), keys=2)  # clip frames 0, 0.5, 1, 1.5, 2 (= 0)
    np.testing.assert_allclose(poses[:, 0, 0], [0, 1, 2, 1, 0])
    halfway = np.array([1 + np.cos(turn / 2), 0, 0, np.sin(turn / 2)])
    np.testing.assert_allclose(poses[1, 0, 3:], halfway / np.linalg.norm(halfway))
    np.testing.assert_allclose(poses[4], poses[0])  # the loop closes


def test_continuous_quaternions_never_point_apart() -> None:
    q = np.array([[1.0, 0, 0, 0], [-0.99, -0.1, 0, 0], [0.98, 0.2, 0, 0]])
    q /= np.linalg.norm(q, axis=-1, keepdims=True)
    out = continuous(q)
    assert (np.einsum("fc,fc->f", out[1:], out[:-1]) > 0).all()
    np.testing.assert_allclose(np.abs(out), np.abs(q))
