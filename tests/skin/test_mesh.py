"""The creature mesh: closed, outward, weighted, textured, at the levels of detail asked."""

from __future__ import annotations

import numpy as np
import pytest

from ecs_tentacles.skin.mesh import Detail, creature_mesh
from ecs_tentacles.skin.skeleton import creature_skeleton
from ecs_tentacles.take import Take


def edges(faces: np.ndarray) -> np.ndarray:
    """Directed edges (3T, 2) of triangles."""
    return faces[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2)


@pytest.mark.parametrize(
    "detail",
    [
        Detail(),
        Detail(rings_per_link=1, sides=8, cap_rings=1),
        Detail(rings_per_link=1, sides=4, cap_rings=1),  # the sandbox's tiny creatures
        Detail(2, 4, 1, suckers=True),
        Detail(6, 16, 4, suckers=True),
    ],
)
def test_the_mesh_is_one_closed_outward_surface(octopus_take: Take, detail: Detail) -> None:
    mesh = creature_mesh(creature_skeleton(octopus_take, 0), detail)
    directed = edges(mesh.faces)
    _, undirected = np.unique(np.sort(directed, axis=1), axis=0, return_counts=True)
    assert set(undirected.tolist()) == {2}  # every edge shared by exactly two faces
    _, once = np.unique(directed, axis=0, return_counts=True)
    assert set(once.tolist()) == {1}  # neighbours run a shared edge in opposite directions
    a, b, c = (mesh.positions[mesh.faces[:, i]] for i in range(3))
    cross = np.cross(b - a, c - a)
    assert np.linalg.norm(cross, axis=1).min() > 1e-9  # no degenerate triangles
    assert np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6 > 0  # encloses positive volume
    # every vertex normal agrees with the faces around it: the surface is outward everywhere
    face_normal = cross / np.linalg.norm(cross, axis=1, keepdims=True)
    for i in range(3):
        assert (np.einsum("ij,ij->i", mesh.normals[mesh.faces[:, i]], face_normal) > 0).all()
    used = np.zeros(len(mesh.positions), bool)
    used[mesh.faces] = True
    assert used.all()
    shells = 1 + (8 * 10 if detail.suckers else 0)
    euler = len(mesh.positions) - len(directed) // 2 + len(mesh.faces)
    assert euler == 2 * shells  # a sphere per shell: one continuous body (+ sucker discs)


def test_weights_sum_to_one_and_follow_the_links(octopus_take: Take) -> None:
    skeleton = creature_skeleton(octopus_take, 0)
    mesh = creature_mesh(skeleton)
    np.testing.assert_allclose(mesh.weights.sum(axis=1), 1.0, atol=1e-12)
    assert (mesh.weights >= 0).all()
    assert set(np.unique(mesh.joints[mesh.weights > 0]).tolist()) == set(range(81))
    # a ring's vertices share their weights; blended rings mix neighbouring joints only
    ring_weights = mesh.weights[mesh.rings]
    np.testing.assert_array_equal(ring_weights, ring_weights[:, :1].repeat(12, axis=1))
    pairs = mesh.joints[mesh.rings[:, 0]]
    mixed = (mesh.weights[mesh.rings[:, 0]] > 0).all(axis=1)
    assert mixed.sum() > 0
    assert (skeleton.parents[pairs[mixed, 1]] == pairs[mixed, 0]).all()


def test_tubes_follow_the_taper_and_end_in_rounded_tips(octopus_take: Take) -> None:
    skeleton = creature_skeleton(octopus_take, 0)
    detail = Detail(rings_per_link=4, sides=12, cap_rings=3)
    mesh = creature_mesh(skeleton, detail)
    tentacle = skeleton.layout.tentacles[3]
    rings = mesh.rings[mesh.ring_tentacle == 3]
    s = mesh.ring_s[mesh.ring_tentacle == 3]
    points = mesh.positions[rings]
    centres = points.mean(axis=1)
    radii = np.linalg.norm(points - centres[:, None], axis=2)
    # link centres carry the link's radius (the thesis's per-link scale)
    joint_s = np.concatenate([[0.0], np.cumsum(tentacle.lengths)])
    middle = joint_s[:-1] + 0.5 * tentacle.lengths
    at_middle = np.isin(np.round(s, 9), np.round(middle, 9))
    np.testing.assert_allclose(radii[at_middle, 0], tentacle.radii, rtol=1e-9)
    assert (np.diff(radii[:, 0]) <= 1e-12).all()  # tapering all the way
    np.testing.assert_allclose(radii, radii[:, :1].repeat(12, axis=1), rtol=1e-9)  # round
    # the centre line runs straight out along the tentacle's axis in the bind pose
    direction = np.array([np.cos(tentacle.angle), np.sin(tentacle.angle)])
    start = centres[0]
    offsets = centres - start
    np.testing.assert_allclose(offsets[:, :2], s[:, None] * direction, atol=1e-9)
    assert len(s) == 10 * 4 + 4
    on_tip = mesh.positions[mesh.joints[:, 0] == tentacle.joints[-1]] - start
    reach = on_tip[:, :2] @ direction
    # the cap is the tip capsule's: it ends one tip radius past the last joint, on the axis
    np.testing.assert_allclose(reach.max(), joint_s[-1] + tentacle.radii[-1], rtol=1e-9)
    np.testing.assert_allclose(on_tip[reach.argmax(), 2], 0.0, atol=1e-12)


def test_uvs_run_around_and_along_each_tentacle(octopus_take: Take) -> None:
    mesh = creature_mesh(creature_skeleton(octopus_take, 0))
    assert mesh.uv.shape == (len(mesh.faces), 3, 2)
    assert mesh.uv.min() >= 0.0 and mesh.uv.max() <= 1.0


def test_levels_of_detail_change_the_vertex_count(octopus_take: Take) -> None:
    skeleton = creature_skeleton(octopus_take, 0)
    lean = creature_mesh(skeleton, Detail(rings_per_link=2, sides=8))
    fine = creature_mesh(skeleton, Detail(rings_per_link=6, sides=16))
    assert len(lean.faces) * 3 < len(fine.faces)
    assert lean.rings.shape[1] == 8 and fine.rings.shape[1] == 16


@pytest.mark.parametrize(
    ("field", "value", "message"),
    [
        ("sides", 10, "sides: must be a multiple of 4 and >= 4, got 10"),
        ("sides", 0, "sides: must be a multiple of 4 and >= 4, got 0"),
        ("rings_per_link", 0, "rings_per_link: must be >= 1, got 0"),
    ],
)
def test_bad_detail_is_one_line(field: str, value: int, message: str) -> None:
    with pytest.raises(ValueError, match=f"^{message}$"):
        Detail(**{field: value})


def test_tentacles_too_thick_for_the_mantle_are_one_line(octopus_take: Take) -> None:
    from dataclasses import replace

    from ecs_tentacles.skin.mesh import MeshError

    skeleton = creature_skeleton(octopus_take, 0)
    fat = [replace(t, radii=t.radii * 3) for t in skeleton.layout.tentacles]
    crowded = replace(skeleton, layout=replace(skeleton.layout, tentacles=fat))
    with pytest.raises(MeshError, match=r"^creature octopus: tentacles t0 and t1 overlap at the"):
        creature_mesh(crowded)
