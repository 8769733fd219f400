"""Skinned glTF: the Khronos validator finds nothing, and skinning the file's own
joints, keys and inverse bind matrices puts the tubes on the simulated links."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

from ecs_tentacles.export.gltf import accessor_array, read_glb, to_y_up_points
from ecs_tentacles.export.skinned import Skin
from ecs_tentacles.export.skinned_gltf import split_by_uv, write_skinned_glb
from ecs_tentacles.skin.keys import slerp
from ecs_tentacles.skin.mesh import creature_mesh
from ecs_tentacles.skin.rig import Keys
from ecs_tentacles.skin.skeleton import creature_skeleton, joint_world_poses
from ecs_tentacles.take import Take
from tests.export.conftest import khronos_report
from tests.skin.cpu_skinning import skin_points, skinning_matrices

ROOT = Path(__file__).resolve().parents[2]


def _accessor(document: dict[str, Any], binary: bytes, index: int) -> np.ndarray:
    """Accessors of any width (the shared reader knows SCALAR, VEC3 and VEC4)."""
    accessor = document["accessors"][index]
    if accessor["type"] in ("SCALAR", "VEC3", "VEC4"):
        return accessor_array(document, binary, index)
    width = {"VEC2": 2, "MAT4": 16}[accessor["type"]]
    view = document["bufferViews"][accessor["bufferView"]]
    flat = np.frombuffer(binary, np.float32, accessor["count"] * width, view["byteOffset"])
    return flat.reshape(accessor["count"], width)


def _matrix(node: dict[str, Any], rotation: np.ndarray, translation: np.ndarray) -> np.ndarray:
    x, y, z, w = rotation / np.linalg.norm(rotation)
    out = np.eye(4)
    out[:3, :3] = [
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ]
    out[:3, 3] = translation
    return out


def _pose(document: dict[str, Any], binary: bytes, seconds: float) -> dict[int, np.ndarray]:
    """Every node's global matrix at `seconds`, sampling the animation like a player does."""
    trs = {
        i: [
            np.array(n.get("rotation", [0, 0, 0, 1.0])),
            np.array(n.get("translation", [0, 0, 0.0])),
        ]
        for i, n in enumerate(document["nodes"])
    }
    (animation,) = document["animations"]
    for channel in animation["channels"]:
        sampler = animation["samplers"][channel["sampler"]]
        times = _accessor(document, binary, sampler["input"]).astype(np.float64)
        values = _accessor(document, binary, sampler["output"]).astype(np.float64)
        k = int(np.clip(np.searchsorted(times, seconds, side="right") - 1, 0, len(times) - 1))
        nxt = min(k + 1, len(times) - 1)
        t = 0.0 if nxt == k else (seconds - times[k]) / (times[nxt] - times[k])
        if channel["target"]["path"] == "rotation":
            xyzw = slerp(values[k][[3, 0, 1, 2]], values[nxt][[3, 0, 1, 2]], np.array(t))
            trs[channel["target"]["node"]][0] = xyzw[[1, 2, 3, 0]]
        else:
            trs[channel["target"]["node"]][1] = (1 - t) * values[k] + t * values[nxt]
    world: dict[int, np.ndarray] = {}

    def visit(index: int, parent: np.ndarray) -> None:
        world[index] = parent @ _matrix(document["nodes"][index], *trs[index])
        for child in document["nodes"][index].get("children", []):
            visit(child, world[index])

    for root in document["scenes"][0]["nodes"]:
        visit(root, np.eye(4))
    return world


@pytest.mark.parametrize("keys", ["all", "reduced"])
def test_skinning_the_file_lands_on_the_simulated_links(
    octopus_take: Take, tmp_path: Path, keys: str
) -> None:
    take = octopus_take
    write_skinned_glb(take, tmp_path / "skinned.glb", Skin(keys=Keys(keys, 0.5)))
    document, binary = read_glb((tmp_path / "skinned.glb").read_bytes())
    (skin,) = document["skins"]
    mesh_node = next(n for n in document["nodes"] if "skin" in n)
    assert mesh_node["name"] == "octopus_skin" and "translation" not in mesh_node
    primitive = document["meshes"][mesh_node["mesh"]]["primitives"][0]
    attributes = primitive["attributes"]
    positions = _accessor(document, binary, attributes["POSITION"]).astype(np.float64)
    joints = _accessor(document, binary, attributes["JOINTS_0"]).astype(np.int64)
    weights = _accessor(document, binary, attributes["WEIGHTS_0"]).astype(np.float64)
    inverse = _accessor(document, binary, skin["inverseBindMatrices"]).reshape(-1, 4, 4)
    inverse = inverse.transpose(0, 2, 1).astype(np.float64)  # column-major storage
    np.testing.assert_allclose(weights.sum(axis=1), 1.0, atol=1e-7)
    skeleton = creature_skeleton(take, 0)
    mesh = creature_mesh(skeleton)
    source, _, _ = split_by_uv(mesh)
    rotation, origin = joint_world_poses(skeleton, take)
    rigid = weights[:, 1] == 0
    # reduced keys: each joint may turn up to 0.5 deg off, which moves everything beyond it
    ancestors = np.eye(len(skeleton.names), dtype=bool)
    for j, parent in enumerate(skeleton.parents):
        if parent >= 0:
            ancestors[j] |= ancestors[parent]
    for frame in (0, 50, 120):
        world = _pose(document, binary, frame / take.fps)
        palette = np.stack([world[j] for j in skin["joints"]]) @ inverse
        blended = np.einsum("vk,vkij->vij", weights, palette[joints])
        skinned = np.einsum("vij,vj->vi", blended[:, :3, :3], positions) + blended[:, :3, 3]
        matrices = skinning_matrices(skeleton, rotation[frame], origin[frame])
        expected = to_y_up_points(skin_points(mesh, matrices))[source]
        error = np.linalg.norm(skinned - expected, axis=1)
        if keys == "all":
            assert error.max() < 1e-3
            continue
        reach = np.linalg.norm(expected[:, None] - to_y_up_points(origin[frame]), axis=2)
        bound = np.radians(0.5) * (reach @ ancestors.T.astype(float))  # (V, J)
        allowed = 0.0005 + np.take_along_axis(bound, joints[:, :2], axis=1).max(axis=1)
        assert (error <= allowed + 1e-4).all() and error[rigid].max() > 0


def test_the_khronos_validator_finds_nothing_in_a_skinned_file(
    guided_take: Take, tmp_path: Path, gltf_validator: tuple[str, Path]
) -> None:
    for keys in ("all", "reduced"):
        path = tmp_path / f"{keys}.glb"
        write_skinned_glb(guided_take, path, Skin(keys=Keys(keys, 0.5)))
        report = khronos_report(path, gltf_validator)
        assert report["issues"]["messages"] == []
        assert (report["issues"]["numErrors"], report["issues"]["numWarnings"]) == (0, 0)
        assert report["info"]["animationCount"] == 1 and report["info"]["drawCallCount"] == 1


def test_a_crowd_on_all_three_tiers_exports_every_creatures_full_skeleton(
    tmp_path: Path,
) -> None:
    """1 full, 2 reduced and 3 replayed creatures: each has its own skin with the full
    skeleton's joints, and every joint plays on the links the take recorded (the reduced
    ones shown on the full skeleton, the replayed ones from their clips)."""
    from ecs_tentacles.export.bake import BakePlan, bake
    from ecs_tentacles.world import World
    from tests.cli.test_measure import lod_crowd

    scene = lod_crowd(6)
    with World.from_scene(scene) as world:
        world.step(60)
        assert world.lod.counts() == {"full": 1, "reduced": 2, "kinematic": 3}
    take = bake(BakePlan.make(scene, seconds=1.0, fps=30.0), progress=False)
    write_skinned_glb(take, tmp_path / "crowd.glb", Skin(keys=Keys("all", 0.5)))
    document, binary = read_glb((tmp_path / "crowd.glb").read_bytes())
    assert len(document["skins"]) == 6
    for creature, skin in enumerate(document["skins"]):
        skeleton = creature_skeleton(take, creature)
        assert len(skin["joints"]) == len(skeleton.names)
        _, origin = joint_world_poses(skeleton, take)
        assert np.isfinite(origin).all()
        for frame in (0, 15, 30):
            world_pose = _pose(document, binary, frame / take.fps)
            played = np.stack([world_pose[j][:3, 3] for j in skin["joints"]])
            expected = to_y_up_points(origin[frame])
            assert np.linalg.norm(played - expected, axis=1).max() < 1e-3, (creature, frame)
        assert np.ptp(origin[:, 0], axis=0).max() > 0.01  # it moved
        child = np.flatnonzero(np.asarray(skeleton.parents) >= 0)
        parent = np.asarray(skeleton.parents)[child]
        bone = np.linalg.norm(origin[:, child] - origin[:, parent], axis=2)  # (frames, bones)
        assert np.ptp(bone, axis=0).max() < 1e-3  # a chain of rigid links, never stretched
