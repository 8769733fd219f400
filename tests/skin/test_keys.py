"""Key reduction: every sample stays within the tolerance, and most keys go."""

from __future__ import annotations

import numpy as np
import pytest

from ecs_tentacles.numeric.quaternions import quat_about_z
from ecs_tentacles.skin.keys import (
    angle_between,
    interpolate_points,
    interpolate_rotations,
    reduce_points,
    reduce_rotations,
)
from ecs_tentacles.skin.rig import Keys, skinned_creatures
from ecs_tentacles.skin.skeleton import creature_animation, creature_skeleton
from ecs_tentacles.take import Take


def test_a_steady_turn_needs_only_its_ends_and_a_kink_keeps_its_corner() -> None:
    steady = quat_about_z(np.linspace(0.0, 1.0, 50))[:, None]  # slerp is exact on it
    keep = reduce_rotations(steady, 0.1)
    assert np.flatnonzero(keep[:, 0]).tolist() == [0, 49]
    there_and_back = quat_about_z(np.r_[np.linspace(0, 1, 20), np.linspace(1, 0, 20)[1:]])
    keep = reduce_rotations(there_and_back[:, None], 0.1)
    assert np.flatnonzero(keep[:, 0]).tolist() == [0, 19, 38]


def test_octopus_keys_at_half_a_degree(octopus_take: Take) -> None:
    animation = creature_animation(creature_skeleton(octopus_take, 0), octopus_take)
    rotation = animation.rotation
    keep = reduce_rotations(rotation, 0.5)
    assert keep[0].all() and keep[-1].all()
    error = angle_between(interpolate_rotations(rotation, keep), rotation)
    assert error.max() <= 0.5  # every sample of every joint within the tolerance
    assert keep.sum() <= rotation.shape[0] * rotation.shape[1] // 2  # at least half dropped
    finer = reduce_rotations(rotation, 0.1)
    assert finer.sum() > keep.sum()
    assert angle_between(interpolate_rotations(rotation, finer), rotation).max() <= 0.1


def test_root_translation_keys_stay_within_their_distance(octopus_take: Take) -> None:
    root = creature_animation(creature_skeleton(octopus_take, 0), octopus_take).translation[:, 0]
    keep = reduce_points(root, 0.0005)
    error = np.linalg.norm(interpolate_points(root, keep) - root, axis=1)
    assert error.max() <= 0.0005 and 2 <= keep.sum() < len(root)


def test_the_report_counts_every_channel(octopus_take: Take) -> None:
    _, everything = skinned_creatures(octopus_take)
    assert everything.before == everything.after == 121 * (81 + 1)
    _, reduced = skinned_creatures(octopus_take, keys=Keys("reduced", 0.5))
    assert reduced.before == everything.before and reduced.after < reduced.before // 2
    assert reduced.max_rotation_error_deg <= 0.5
    assert "keys 9922 -> " in reduced.line()
    assert everything.line() == (
        "9922 keys (every frame: nothing reduced; --keys reduced keeps fewer)"
    )


@pytest.mark.parametrize(
    ("mode", "tolerance", "message"),
    [
        ("some", 0.5, "keys: must be one of all, reduced, got 'some'"),
        ("reduced", 0.0, "key tolerance: must be > 0 degrees, got 0.0"),
    ],
)
def test_bad_key_options_are_one_line(mode: str, tolerance: float, message: str) -> None:
    with pytest.raises(ValueError, match=f"^{message}$"):
        Keys(mode, tolerance)
