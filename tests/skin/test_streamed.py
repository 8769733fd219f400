"""Joint rotations chunk by chunk: the same rotations as from the whole take at once, with
signs continuous across the chunks' seams, for every creature of a body plan at once."""

from __future__ import annotations

import numpy as np

from ecs_tentacles.numeric.quaternions import quat_rotate
from ecs_tentacles.skin.skeleton import (
    creature_animation,
    creature_skeleton,
    joint_world_poses,
    quat_conjugate,
)
from ecs_tentacles.skin.streamed import JointRotations
from ecs_tentacles.take import Take


def test_chunks_give_the_whole_takes_rotations_signs_and_all(octopus_take: Take) -> None:
    take = octopus_take
    skeleton = creature_skeleton(take, 0)
    whole = creature_animation(skeleton, take).rotation
    rotations = JointRotations(skeleton.parents, skeleton.bodies[None, :])
    pieces = [rotations.local(take.quat[first : first + 7]) for first in range(0, take.frames, 7)]
    chunked = np.concatenate(pieces)[:, 0]
    np.testing.assert_allclose(chunked, whole, atol=1e-12)
    # no seam takes the long way round: neighbouring frames in one hemisphere
    assert (np.einsum("fjc,fjc->fj", chunked[1:], chunked[:-1]) > 0).all()


def test_a_joints_offset_in_its_parent_is_constant_to_float_precision(octopus_take: Take) -> None:
    """Why the skinned USD writes joint translations once: in the simulated take every
    joint (a link's base) stays at its rest offset in its parent body, within float32
    rounding of the stored poses (6e-8 m here), while the tentacles move by decimetres."""
    take = octopus_take
    skeleton = creature_skeleton(take, 0)
    rotation, origin = joint_world_poses(skeleton, take)
    children = np.flatnonzero(skeleton.parents >= 0)
    parents = skeleton.parents[children]
    offset = quat_rotate(
        quat_conjugate(rotation[:, parents]), origin[:, children] - origin[:, parents]
    )
    drift = np.linalg.norm(offset - skeleton.rest_translation[children], axis=-1)
    assert drift.max() < 1e-6
    assert np.linalg.norm(origin[-1] - origin[0], axis=-1).max() > 0.1


def test_rotations_of_some_frames_only_match_the_whole_ones(octopus_take: Take) -> None:
    """`local_at` (the creature-frames a USD animation samples, here every third frame in
    chunks of 7) gives the rotations `local` gives at those frames, turned by a heading
    the same way, signs continuous from one sampled frame to the next."""
    take = octopus_take
    skeleton = creature_skeleton(take, 0)
    yaw = np.linspace(0.0, 4.0, take.frames)[:, None]
    whole = JointRotations(skeleton.parents, skeleton.bodies[None, :]).local(take.quat, yaw)
    some = JointRotations(skeleton.parents, skeleton.bodies[None, :])
    picked, found = np.arange(0, take.frames, 3), []
    for first in range(0, take.frames, 7):
        rows = picked[(picked >= first) & (picked < first + 7)] - first
        columns = np.zeros(len(rows), dtype=np.int64)
        found.append(
            some.local_at(take.quat[first : first + 7], rows, columns, yaw[rows + first, 0])
        )
    at = np.concatenate(found)
    dot = np.abs(np.einsum("fjc,fjc->fj", at, whole[picked, 0]))
    np.testing.assert_allclose(dot, 1.0, atol=1e-12)
    assert (np.einsum("fjc,fjc->fj", at[1:], at[:-1]) > 0).all()
