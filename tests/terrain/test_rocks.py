"""Boulders: a `rock` obstacle is the same stone for the same seed, collides as it is drawn
and exports as it is drawn; `crowd N --terrain rocky` puts enough of them, large enough,
among the creatures that they bend the creatures' paths without walling anyone in."""

from __future__ import annotations

import json
import pathlib
from typing import Any

import mujoco
import numpy as np
import pytest

from ecs_tentacles.cli import main
from ecs_tentacles.export.glb import accessor_array, read_glb
from ecs_tentacles.locomotion.navigation import CostGrid
from ecs_tentacles.scene.construction import creature_reach
from ecs_tentacles.terrain.ground import TerrainGround
from ecs_tentacles.terrain.rocks import rock_vertices
from ecs_tentacles.terrain.scene_ground import build_ground

ROCKS = {
    "heightfield": {"size": [6, 6], "resolution": 25, "height": 0.4, "noise": {"seed": 2}},
    "obstacles": [
        {"shape": "rock", "position": [1.5, 0.5, 0.1], "size": [0.9, 0.6, 0.5], "seed": 4},
        {"shape": "rock", "position": [-1.5, -1.0, 0.05], "size": [0.5, 0.5, 0.3],
         "rotation_deg": [0, 0, 40]},
    ],
}  # fmt: skip


def _ground(terrain: dict[str, Any]) -> TerrainGround:
    ground = build_ground(terrain, None)
    assert isinstance(ground, TerrainGround)
    return ground


def test_a_rock_is_the_same_stone_for_the_same_seed_and_fills_its_box() -> None:
    one = rock_vertices((0.9, 0.6, 0.5), 4)
    np.testing.assert_array_equal(one, rock_vertices((0.9, 0.6, 0.5), 4))
    other = rock_vertices((0.9, 0.6, 0.5), 5)
    assert one.shape != other.shape or not np.allclose(one, other)
    np.testing.assert_allclose(one.max(axis=0) - one.min(axis=0), [0.9, 0.6, 0.5])
    np.testing.assert_allclose(one.max(axis=0), -one.min(axis=0))  # centred on its box
    # not a sphere or a box: the distance from the middle varies by a fifth and more
    radii = np.linalg.norm(one / [0.45, 0.3, 0.25], axis=1)
    assert radii.max() / radii.min() > 1.2
    assert 30 <= len(one) <= 100  # faceted, and few points for MuJoCo's collisions


def test_a_rock_collides_as_it_is_drawn_and_sits_in_the_ground() -> None:
    ground = _ground(ROCKS)
    drawn = next(m for m in ground.meshes() if m.name == "obstacles").mesh
    model, data = ground._static()
    field = ground.heightfield
    assert field is not None
    for k, solid in enumerate(ground.solids):
        assert solid.kind == "mesh" and len(solid.pieces) == 1
        geom = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, f"ground/solid{k}/piece0")
        mesh = model.geom_dataid[geom]
        start, count = model.mesh_vertadr[mesh], model.mesh_vertnum[mesh]
        local = model.mesh_vert[start : start + count].astype(np.float64)
        world = local @ data.geom_xmat[geom].reshape(3, 3).T + data.geom_xpos[geom]
        # MuJoCo's vertices are the drawn mesh's corners (float32 in MuJoCo)
        gaps = np.linalg.norm(world[:, None, :] - drawn.vertices[None, :, :], axis=2).min(axis=1)
        assert gaps.max() < 1e-5, k
        outline = solid.pieces[0] @ solid.rotation.T + solid.position
        lowest_ground = field.height(outline[:, :2]).min()
        assert outline[:, 2].min() <= lowest_ground + 1e-9  # no side in the air
        assert outline[:, 2].max() > field.height(outline[:, :2]).max() + 0.1  # it shows


def test_rocks_export_to_usd_and_gltf_as_they_are_drawn(tmp_path: pathlib.Path) -> None:
    pytest.importorskip("pxr", reason="USD export needs usd-core")
    from pxr import Usd, UsdGeom

    scene = {
        "version": 1,
        "terrain": ROCKS,
        "creatures": [{"name": "octo", "position": [0, 0], "tentacles": {"count": 3, "links": 3}}],
    }
    (tmp_path / "rocks.json").write_text(json.dumps(scene))
    take = tmp_path / "rocks.npz"
    assert main(["bake", str(tmp_path / "rocks.json"), "--seconds", "0.05", "--out", str(take),
                 "--quiet"]) == 0  # fmt: skip
    drawn = next(m for m in _ground(ROCKS).meshes() if m.name == "obstacles").mesh
    for suffix in (".usdc", ".glb"):
        assert main(["export", str(take), "--out", str(tmp_path / f"rocks{suffix}")]) == 0
    stage = Usd.Stage.Open(str(tmp_path / "rocks.usdc"))
    usd = UsdGeom.Mesh(stage.GetPrimAtPath("/World/terrain/obstacles"))
    np.testing.assert_allclose(np.array(usd.GetPointsAttr().Get()), drawn.vertices, atol=1e-6)
    document, binary = read_glb((tmp_path / "rocks.glb").read_bytes())
    node = next(n for n in document["nodes"] if n.get("name") == "terrain/obstacles")
    primitive = document["meshes"][node["mesh"]]["primitives"][0]
    points = accessor_array(document, binary, primitive["attributes"]["POSITION"])
    y_up = drawn.vertices[:, [0, 2, 1]] * [1.0, 1.0, -1.0]  # glTF is y-up: (x, z, -y)
    np.testing.assert_allclose(points, y_up, atol=1e-6)


def test_a_rocky_crowd_has_boulders_that_bend_its_paths(tmp_path: pathlib.Path) -> None:
    """`crowd 24 --terrain rocky` put 5 spheres of 0.24-0.57 m across at the crowd's edge
    (none on a path: every creature crawled straight). Now a dozen and more boulders
    0.36-1.2 m across stand between the creatures: a third or more of the routes the
    path finder plans bend round them, every creature has one, and no tentacle starts
    inside a rock."""
    out = tmp_path / "crowd.json"
    assert main(["crowd", "24", "--terrain", "rocky", "--out", str(out)]) == 0
    scene = json.loads(out.read_text())
    rocks = scene["terrain"]["obstacles"]
    assert len(rocks) >= 12 and {r["shape"] for r in rocks} == {"rock"}
    across = np.array([max(r["size"][:2]) for r in rocks])
    assert across.min() >= 0.36 - 1e-9 and across.max() <= 1.2 + 1e-9
    assert np.median(across) >= 0.5
    ground = _ground(scene["terrain"])
    starts = np.array([c["position"] for c in scene["creatures"]])
    goals = np.array([c["goals"][0]["position"] for c in scene["creatures"]])
    reach = max(creature_reach(c) for c in scene["creatures"])
    for solid in ground.solids:
        footprint = solid.pieces[0] @ solid.rotation.T + solid.position
        gaps = np.linalg.norm(footprint[:, None, :2] - starts[None, :, :], axis=2)
        assert gaps.min() > reach
    grid = CostGrid.of(ground, reach=reach, around=np.vstack([starts, goals]))
    assert grid is not None
    routes = [grid.route(s, g) for s, g in zip(starts, goals, strict=True)]
    assert all(r is not None for r in routes)
    bent = sum(len(r) > 1 for r in routes if r is not None)
    assert bent >= len(routes) // 3
