"""glTF export: nodes, animation values (turned y-up), lean meshes, the Khronos validator."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from ecs_tentacles.export.gltf import (
    accessor_array,
    read_glb,
    to_y_up_points,
    to_y_up_rotations,
    write_glb,
)
from ecs_tentacles.export.meshes import body_mesh
from ecs_tentacles.take import Take
from tests.export.conftest import khronos_report

ROOT = Path(__file__).resolve().parents[2]


def test_nodes_and_animation_hold_the_take_turned_y_up(guided_take: Take, tmp_path: Path) -> None:
    take = guided_take
    write_glb(take, tmp_path / "take.glb")
    document, binary = read_glb((tmp_path / "take.glb").read_bytes())
    nodes = document["nodes"]
    assert nodes[0]["name"] == "World" and document["scenes"][0]["nodes"] == [0]
    creature = nodes[nodes[0]["children"][0]]
    assert creature["name"] == "octo"
    mantle, tentacles = (nodes[i] for i in creature["children"])
    assert (mantle["name"], tentacles["name"]) == ("octo_mantle", "octo_tentacles")
    assert [nodes[i]["name"] for i in tentacles["children"]] == ["octo_t0", "octo_t1", "octo_t2"]
    names = [node["name"] for node in nodes]
    assert len(set(names)) == len(names)  # every node its own name: importers rename none
    (animation,) = document["animations"]
    assert len(animation["channels"]) == 2 * len(take.header["bodies"])
    by_target = {(c["target"]["node"], c["target"]["path"]): c for c in animation["channels"]}
    times = accessor_array(document, binary, animation["samplers"][0]["input"])
    np.testing.assert_array_equal(times, take.times.astype(np.float32))
    link = nodes[tentacles["children"][2]]["children"][1]  # t2/link1
    index = take.body("octo/tentacles/t2/link1")
    for path, expected in (
        ("translation", to_y_up_points(take.pos[:, index]).astype(np.float32)),
        ("rotation", to_y_up_rotations(take.quat[:, index]).astype(np.float32)),
    ):
        sampler = animation["samplers"][by_target[(link, path)]["sampler"]]
        assert sampler["interpolation"] == "LINEAR"
        np.testing.assert_array_equal(accessor_array(document, binary, sampler["output"]), expected)
    # frame 0 rest pose: z-up (x, y, z) is y-up (x, z, -y); the mantle stands along +y
    x, y, z = take.pos[0, 0]
    np.testing.assert_allclose(mantle["translation"], [x, z, -y], atol=1e-7)
    np.testing.assert_allclose(mantle["rotation"], [0, 0, 0, 1], atol=1e-7)
    positions = accessor_array(
        document, binary, document["meshes"][0]["primitives"][0]["attributes"]["POSITION"]
    )
    np.testing.assert_allclose(positions[:, 1].max(), 0.1, atol=1e-7)  # half the mantle height
    assert document["asset"]["extras"]["scene_sha256"] == take.header["scene_sha256"]


def test_rotations_about_z_become_rotations_about_y() -> None:
    angle = 0.7
    z_up = np.array([np.cos(angle / 2), 0.0, 0.0, np.sin(angle / 2)])
    np.testing.assert_allclose(
        to_y_up_rotations(z_up), [0.0, np.sin(angle / 2), 0.0, np.cos(angle / 2)], atol=1e-15
    )


@pytest.mark.parametrize(("shape", "axis"), [("capsule", "X"), ("cylinder", "Z")])
def test_meshes_are_closed_outward_and_have_no_degenerate_triangles(shape: str, axis: str) -> None:
    mesh = body_mesh(shape, axis, 0.03, 0.08)
    triangles = mesh.positions[mesh.indices.reshape(-1, 3)].astype(np.float64)
    a, b, c = triangles[:, 0], triangles[:, 1], triangles[:, 2]
    face = np.cross(b - a, c - a)
    assert np.linalg.norm(face, axis=1).min() > 1e-8
    centre = triangles.mean(axis=1)  # the body is convex and centred: outward = away from 0
    assert (np.einsum("ij,ij->i", face, centre) > 0).all()
    # rims repeat vertices with another normal: weld by position before counting edges
    _, welded = np.unique(mesh.positions.round(9), axis=0, return_inverse=True)
    corners = welded.reshape(-1)[mesh.indices.reshape(-1, 3)]
    edges = np.sort(corners[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)
    _, counts = np.unique(edges, axis=0, return_counts=True)
    assert set(counts.tolist()) == {2}  # every edge shared by two triangles: watertight
    extent = np.abs(mesh.positions).max(axis=0)
    expected = [0.07, 0.03, 0.03] if shape == "capsule" else [0.03, 0.03, 0.04]
    np.testing.assert_allclose(extent, expected, rtol=1e-6)


def test_the_khronos_validator_finds_nothing(
    guided_take: Take, tmp_path: Path, gltf_validator: tuple[str, Path]
) -> None:
    write_glb(guided_take, tmp_path / "take.glb")
    report = khronos_report(tmp_path / "take.glb", gltf_validator)
    assert report["issues"]["messages"] == []
    assert (report["issues"]["numErrors"], report["issues"]["numWarnings"]) == (0, 0)
    assert report["info"]["animationCount"] == 1
    assert report["info"]["drawCallCount"] == 1 + 4  # the mantle + 4 link sizes, shared
