"""Skinned USD: a SkelRoot per creature that passes USD's validators (UsdSkel's included)
and that USD's own skinning turns back into the simulated tentacles."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

from ecs_tentacles.cli import main
from ecs_tentacles.export.skinned import Skin
from ecs_tentacles.export.skinned_usd import build_skinned_stage, write_skinned_usd
from ecs_tentacles.export.usd_curves import TOLERANCE
from ecs_tentacles.export.usd_validation import usd_problems
from ecs_tentacles.numeric.quaternions import quat_rotate
from ecs_tentacles.skin.keys import angle_between
from ecs_tentacles.skin.mesh import Detail, creature_mesh
from ecs_tentacles.skin.rig import Keys
from ecs_tentacles.skin.skeleton import (
    creature_animation,
    creature_skeleton,
    joint_world_poses,
    quat_matrix,
)
from ecs_tentacles.take import Take
from tests.skin.cpu_skinning import skin_points, skinning_matrices

pxr = pytest.importorskip("pxr", reason="USD export needs usd-core (the usd / dev extras)")
from pxr import Usd, UsdGeom, UsdSkel, Vt  # noqa: E402


@pytest.mark.parametrize(
    ("suffix", "keys", "locators"), [(".usda", "all", False), (".usdc", "reduced", True)]
)
def test_the_skinned_stage_passes_the_usd_validators(
    guided_take: Take, tmp_path: Path, suffix: str, keys: str, locators: bool
) -> None:
    path = tmp_path / f"take{suffix}"
    write_skinned_usd(guided_take, path, Skin(keys=Keys(keys, 0.5)), locators=locators)
    assert usd_problems(path) == []
    stage = Usd.Stage.Open(str(path))
    root = stage.GetPrimAtPath("/World/octo")
    assert root.GetTypeName() == "SkelRoot"
    located = ["octo_suckers", "octo_goals"] if locators else []
    assert [p.GetName() for p in root.GetChildren()] == [  # unique names, after it
        "octo_skeleton",
        "octo_skin",
        *located,
        "octo_fur",
    ]
    skeleton = UsdSkel.Skeleton(stage.GetPrimAtPath("/World/octo/octo_skeleton"))
    assert len(skeleton.GetJointsAttr().Get()) == 1 + 3 * 4
    assert len(skeleton.GetRestTransformsAttr().Get()) == 13
    take = guided_take
    curves = UsdGeom.BasisCurves(stage.GetPrimAtPath("/World/octo/octo_fur/octo_guides"))
    sucker = stage.GetPrimAtPath(
        "/World/octo/octo_suckers/octo_t0/octo_t0_link3/octo_t0_link3_sucker0"
    )
    goal = stage.GetPrimAtPath("/World/octo/octo_goals/octo_goal0")
    assert bool(sucker) is bool(goal) is locators
    entry = take.header["suckers"][take.header["suckers"].index(
        next(s for s in take.header["suckers"] if s["name"] == "octo/tentacles/t0/link3/sucker0")
    )]  # fmt: skip
    for frame in (0, 3, take.frames - 1):  # world positions, below the moving SkelRoot
        points = _world(curves.GetPrim(), frame, np.array(curves.GetPointsAttr().Get(frame)))
        expected = take.tracks["guide_points"][frame].reshape(-1, 3)
        np.testing.assert_allclose(points, expected, atol=TOLERANCE)  # held where still
        if locators:
            quat = take.quat[frame, entry["body"]].astype(np.float64)
            point = take.pos[frame, entry["body"]] + quat_rotate(quat, np.array(entry["offset"]))
            np.testing.assert_allclose(_world(sucker, frame, np.zeros((1, 3)))[0], point, atol=1e-6)
            np.testing.assert_allclose(
                _world(goal, frame, np.zeros((1, 3)))[0], take.tracks["goal_pos"][0], atol=1e-6
            )
    if locators:
        assert sucker.GetAttribute("ecs:attached").Get(0) is False


def _world(prim: Any, frame: int, points: np.ndarray) -> np.ndarray:
    """`points` (N, 3) in `prim`'s space, in the world at `frame`."""
    matrix = np.array(UsdGeom.XformCache(frame).GetLocalToWorldTransform(prim))
    return np.asarray(points, np.float64) @ matrix[:3, :3] + matrix[3, :3]  # row vectors


def _skinned(stage: Any, creature: str, frame: int) -> np.ndarray:
    """The mesh points in the world as USD poses them at `frame`: UsdSkel's own skinning
    (skeleton space), then the Skeleton's world transform (USD's definition: a skinned
    prim's own transform is ignored)."""
    cache = UsdSkel.Cache()
    root = UsdSkel.Root(stage.GetPrimAtPath(f"/World/{creature}"))
    cache.Populate(root, Usd.TraverseInstanceProxies())
    skeleton = stage.GetPrimAtPath(f"/World/{creature}/{creature}_skeleton")
    skel = cache.GetSkelQuery(UsdSkel.Skeleton(skeleton))
    skinning = cache.GetSkinningQuery(stage.GetPrimAtPath(f"/World/{creature}/{creature}_skin"))
    xforms = skel.ComputeSkinningTransforms(frame)
    points = Vt.Vec3fArray(UsdGeom.Mesh(skinning.GetPrim()).GetPointsAttr().Get())
    assert skinning.ComputeSkinnedPoints(xforms, points, frame)
    return _world(skeleton, frame, np.array(points, dtype=np.float64))


def test_usd_skinning_puts_the_tubes_on_the_simulated_links(octopus_take: Take) -> None:
    take = octopus_take
    stage, _ = build_skinned_stage(take)
    skeleton = creature_skeleton(take, 0)
    mesh = creature_mesh(skeleton, Detail())
    rotation, origin = joint_world_poses(skeleton, take)
    rigid = mesh.weights[mesh.rings[:, 0], 1] == 0  # rings on one link only
    rigid &= mesh.joints[mesh.rings[:, 0], 0] > 0
    for frame in (0, 37, 120):
        points = _skinned(stage, "octopus", frame)
        centres = points[mesh.rings].mean(axis=1)
        # the same blend of the simulated link poses, straight from the take
        expected = skin_points(mesh, skinning_matrices(skeleton, rotation[frame], origin[frame]))
        np.testing.assert_allclose(centres, expected[mesh.rings].mean(axis=1), atol=1e-3)
        assert np.abs(points - expected).max() < 1e-3
        # rings bound to one link lie on that link's capsule axis in the simulation
        joint = mesh.joints[mesh.rings[rigid, 0], 0]
        body = skeleton.bodies[joint]
        axis_point = take.pos[frame, body]
        quat = take.quat[frame, body].astype(np.float64)
        direction = quat_rotate(quat, np.array([1.0, 0.0, 0.0]))
        offset = centres[rigid] - axis_point
        along = np.einsum("ij,ij->i", offset, direction)
        off_axis = np.linalg.norm(offset - along[:, None] * direction, axis=1)
        assert off_axis.max() < 1e-3
        lengths = np.array([take.header["bodies"][b]["length"] for b in body])
        radii = np.array([take.header["bodies"][b]["radius"] for b in body])
        assert (np.abs(along) <= 0.5 * lengths + radii + 1e-3).all()
    assert np.abs(origin[120] - origin[0]).max() > 0.05  # the creature did move


def test_reduced_keys_stay_within_the_tolerance_through_usd_interpolation(
    octopus_take: Take,
) -> None:
    stage, report = build_skinned_stage(octopus_take, Skin(keys=Keys("reduced", 0.5)))
    animation = UsdSkel.Animation(
        stage.GetPrimAtPath("/World/octopus/octopus_skeleton/octopus_animation")
    )
    samples = animation.GetRotationsAttr().GetTimeSamples()
    assert 3 <= len(samples) <= octopus_take.frames
    expected = creature_animation(creature_skeleton(octopus_take, 0), octopus_take).rotation
    for frame in range(octopus_take.frames):  # between samples USD interpolates (slerp)
        got = np.array(
            [[q.GetReal(), *q.GetImaginary()] for q in animation.GetRotationsAttr().Get(frame)]
        )
        assert angle_between(got, expected[frame]).max() <= 0.5 + 1e-3
    assert report.after < report.before // 2
    assert report.max_rotation_error_deg <= 0.5


def _joint_bodies(entry: dict[str, Any], joints: list[str]) -> list[int]:
    """The take body of each USD joint, read from its name (`mantle/t2_link0/t2_link1`)."""
    bodies = []
    for joint in joints:
        leaf = joint.rsplit("/", 1)[-1]
        if leaf == "mantle":
            bodies.append(entry["mantle"])
        else:
            tentacle, link = leaf.removeprefix("t").split("_link")
            bodies.append(entry["tentacles"][int(tentacle)][int(link)])
    return bodies


def test_usd_skel_evaluates_every_joint_where_the_take_has_its_body(tmp_path: Path) -> None:
    """A bundled scene baked and exported skinned (.usdc) as a user would, read back
    through UsdSkel's own evaluation (`UsdSkel.Cache`, world-space joint transforms, as
    USD clients pose a skeleton): every joint of every creature sits at its body's hinge
    point (the link's base, local x = -L/2; the mantle's centre) within 1 mm and turns
    with its body within 0.01 degrees, at the first, a middle and the last frame."""
    take_path, usd_path = tmp_path / "flock.npz", tmp_path / "flock.usdc"
    bake = ["bake", "flock", "--seconds", "0.5", "--fps", "30", "--out", str(take_path)]
    assert main([*bake, "--quiet"]) == 0
    assert main(["export", str(take_path), "--out", str(usd_path), "--quiet", "--validate"]) == 0
    take = Take.load(take_path)
    stage = Usd.Stage.Open(str(usd_path))
    cache = UsdSkel.Cache()
    lengths = np.array([body["length"] for body in take.header["bodies"]])
    moved = 0.0
    for entry in take.header["creatures"]:
        name = entry["name"]
        cache.Populate(
            UsdSkel.Root(stage.GetPrimAtPath(f"/World/{name}")), Usd.TraverseInstanceProxies()
        )
        query = cache.GetSkelQuery(
            UsdSkel.Skeleton(stage.GetPrimAtPath(f"/World/{name}/{name}_skeleton"))
        )
        bodies = np.array(_joint_bodies(entry, [str(j) for j in query.GetJointOrder()]))
        assert sorted(bodies) == sorted(
            [entry["mantle"], *(b for chain in entry["tentacles"] for b in chain)]
        )
        offset = np.zeros((len(bodies), 3))
        offset[:, 0] = np.where(bodies == entry["mantle"], 0.0, -0.5 * lengths[bodies])
        hinges = []
        for frame in (0, take.frames // 2, take.frames - 1):
            world = np.array(query.ComputeJointWorldTransforms(UsdGeom.XformCache(frame)))
            quat = take.quat[frame, bodies].astype(np.float64)
            quat /= np.linalg.norm(quat, axis=1, keepdims=True)
            hinge = take.pos[frame, bodies] + quat_rotate(quat, offset)
            # USD matrices act on row vectors: the translation is the last row
            assert np.linalg.norm(world[:, 3, :3] - hinge, axis=1).max() < 1e-3
            apart = np.linalg.norm(
                np.swapaxes(world[:, :3, :3], 1, 2) - quat_matrix(quat), axis=(1, 2)
            )
            assert np.degrees(2 * np.arcsin(apart / np.sqrt(8))).max() < 0.01
            hinges.append(world[:, 3, :3])
        moved = max(moved, float(np.linalg.norm(hinges[-1] - hinges[0], axis=1).max()))
    assert moved > 0.05  # the tentacles did move: the poses compared are not the bind pose
