"""The skeleton: hierarchy, bind pose = the built pose, animation that reproduces the take."""

from __future__ import annotations

import numpy as np

from ecs_tentacles.skin.mesh import creature_mesh
from ecs_tentacles.skin.skeleton import (
    creature_animation,
    creature_skeleton,
    forward,
    joint_world_poses,
    transforms,
)
from ecs_tentacles.take import Take
from tests.skin.cpu_skinning import skin_points, skinning_matrices


def test_one_joint_per_body_mantle_first_links_chained(octopus_take: Take) -> None:
    skeleton = creature_skeleton(octopus_take, 0)
    assert len(skeleton.names) == 81 and skeleton.names[0] == "mantle"
    assert skeleton.names[1:3] == ["mantle/t0_link0", "mantle/t0_link0/t0_link1"]
    assert skeleton.names[11] == "mantle/t1_link0"
    assert skeleton.parents[0] == -1 and skeleton.parents[1] == 0 and skeleton.parents[11] == 0
    assert (skeleton.parents[2:11] == np.arange(1, 10)).all()
    names = octopus_take.body_names
    assert [names[b] for b in skeleton.bodies[:3]] == [
        "octopus/mantle",
        "octopus/tentacles/t0/link0",
        "octopus/tentacles/t0/link1",
    ]


def test_the_bind_pose_is_the_built_pose_which_is_frame_zero(octopus_take: Take) -> None:
    skeleton = creature_skeleton(octopus_take, 0)
    rotation, origin = joint_world_poses(skeleton, octopus_take)
    np.testing.assert_allclose(skeleton.bind, transforms(rotation[0], origin[0]), atol=2e-7)
    mesh = creature_mesh(skeleton)
    matrices = skinning_matrices(skeleton, rotation[0], origin[0])
    np.testing.assert_allclose(skin_points(mesh, matrices), mesh.positions, atol=1e-6)


def test_local_rotations_rebuild_the_simulated_poses(octopus_take: Take) -> None:
    skeleton = creature_skeleton(octopus_take, 0)
    animation = creature_animation(skeleton, octopus_take)
    assert animation.rotation.shape == (121, 81, 4)
    # only the root moves by translation; links keep their rest offsets (hinges)
    np.testing.assert_array_equal(
        animation.translation[:, 1:], np.broadcast_to(skeleton.rest_translation[1:], (121, 80, 3))
    )
    rotation, origin = joint_world_poses(skeleton, octopus_take)
    world_r, world_t = forward(skeleton.parents, animation.rotation, animation.translation)
    np.testing.assert_allclose(world_t, origin, atol=1e-5)
    dots = np.abs(np.einsum("fjc,fjc->fj", world_r, rotation))
    assert np.degrees(2 * np.arccos(np.clip(dots, -1, 1))).max() < 0.01
    # continuous signs: neighbouring keys never take the long way round
    steps = np.einsum("fjc,fjc->fj", animation.rotation[1:], animation.rotation[:-1])
    assert (steps > 0).all()
    assert np.abs(octopus_take.pos[-1, 0] - octopus_take.pos[0, 0]).max() > 0.05  # it moved
