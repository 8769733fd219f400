"""The terrain in takes and exports: a take on terrain carries the heightfield and the
obstacles as meshes, readers refuse a hand-edited one, and the USD and glTF exports
(rigid and skinned) hold them as static meshes with a material, clean for the checkers."""

from __future__ import annotations

import json
import zipfile
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from ecs_tentacles.export.gltf import read_glb, write_glb
from ecs_tentacles.export.skinned_gltf import write_skinned_glb
from ecs_tentacles.export.usd_validation import usd_problems
from ecs_tentacles.ground import ground_of
from ecs_tentacles.skin.colours import to_linear
from ecs_tentacles.take import Take, write_npz
from ecs_tentacles.take.read import TakeError
from ecs_tentacles.terrain.ground_meshes import COLOURS
from tests.export.conftest import khronos_report, record

ROOT = Path(__file__).resolve().parents[2]
TERRAIN_SCENE = {
    "version": 1,
    "terrain": {
        "heightfield": {"size": [6, 6], "resolution": 17, "height": 0.3, "noise": {"seed": 2}},
        "obstacles": [
            {"shape": "box", "position": [1.8, 0, 0.2], "size": [0.4, 1.0, 0.4]},
            {"shape": "sphere", "position": [-1.8, 1.0, 0.1], "radius": 0.3},
        ],
    },
    "creatures": [{"name": "octo", "position": [0, 0], "tentacles": {"count": 3, "links": 3}}],
}


@pytest.fixture(scope="module")
def terrain_take() -> Iterator[Take]:
    world, system = record(TERRAIN_SCENE, 6)
    take = system.take()
    names = [part.name for part in ground_of(world).meshes() if part.recorded]
    assert names == ["terrain", "obstacles"]
    yield take
    world.close()


def test_a_take_on_terrain_holds_its_meshes_and_reads_back(
    terrain_take: Take, tmp_path: Path
) -> None:
    names = [name for name, _ in terrain_take.ground_meshes()]
    assert names == ["terrain", "obstacles"]
    terrain_take.save(tmp_path / "t.npz")
    again = Take.load(tmp_path / "t.npz")
    for (name, mesh), (_, back) in zip(
        terrain_take.ground_meshes(), again.ground_meshes(), strict=True
    ):
        np.testing.assert_array_equal(mesh.triangles, back.triangles, err_msg=name)
        np.testing.assert_array_equal(mesh.vertices, back.vertices, err_msg=name)
    assert again.header["ground"]["meshes"][0] == {
        "name": "terrain",
        "vertices": 17 * 17,
        "triangles": 2 * 16 * 16,
        "rgb": list(COLOURS["terrain"]),  # the colour it was drawn in travels with it
    }
    assert again.ground_colours() == {name: COLOURS[name] for name in ("terrain", "obstacles")}


def _rewrite(path: Path, out: Path, change: dict[str, np.ndarray]) -> None:
    """`path` with arrays replaced; a new header keeps what the file's said of its layout
    (its chunks)."""
    with np.load(path) as data:
        arrays = {name: data[name] for name in data.files}
    layout = {k: v for k, v in json.loads(arrays["header"].tobytes()).items()
              if k in ("chunk_frames", "chunked")}  # fmt: skip
    arrays.update(change)
    if "header" in change:
        header = {**json.loads(change["header"].tobytes()), **layout}
        arrays["header"] = np.frombuffer(json.dumps(header).encode(), np.uint8)
    write_npz(out, arrays)


def test_a_hand_edited_ground_is_refused_with_one_line(terrain_take: Take, tmp_path: Path) -> None:
    terrain_take.save(tmp_path / "t.npz")
    triangles = terrain_take.tracks["ground_obstacles_triangles"].copy()
    triangles[0, 0] = 10**6
    _rewrite(tmp_path / "t.npz", tmp_path / "bad.npz", {"ground_obstacles_triangles": triangles})
    with pytest.raises(TakeError, match=r"ground_obstacles_triangles: index 1000000 past the"):
        Take.load(tmp_path / "bad.npz")
    header = dict(terrain_take.header)
    for mesh, says in (
        (
            {"name": "lava flow", "vertices": 3, "triangles": 1},
            r"\[0\]\.name: must be an identifier",
        ),
        ({"name": "lava", "vertices": 3, "triangles": 1, "rgb": [2, 0, 0]}, r"\[0\]\.rgb: must be"),
        ({"name": "lava", "vertices": 3, "triangles": 1}, r"unknown entry 'ground_terrain_points"),
    ):
        header["ground"] = {"digest": "x", "meshes": [mesh]}
        text = json.dumps(header).encode()
        lava = tmp_path / "lava.npz"
        _rewrite(tmp_path / "t.npz", lava, {"header": np.frombuffer(text, np.uint8)})
        with pytest.raises(TakeError, match=says):
            Take.load(lava)
    without = dict(terrain_take.header)
    without.pop("ground")  # arrays the header no longer declares
    text = json.dumps(without).encode()
    _rewrite(tmp_path / "t.npz", tmp_path / "extra.npz", {"header": np.frombuffer(text, np.uint8)})
    with pytest.raises(TakeError, match=r"unknown entry 'ground_terrain_points.npy'"):
        Take.load(tmp_path / "extra.npz")
    with zipfile.ZipFile(tmp_path / "t.npz") as archive:
        assert "ground_terrain_points.npy" in archive.namelist()


def test_the_plane_writes_no_ground(tmp_path: Path) -> None:
    scene = {**TERRAIN_SCENE, "terrain": {}}
    world, system = record(scene, 2)
    take = system.take()
    world.close()
    assert "ground" not in take.header and take.ground_meshes() == []


@pytest.mark.parametrize("skinned", [False, True], ids=["rigid", "skinned"])
def test_usd_holds_the_terrain_as_meshes_with_materials(
    terrain_take: Take, tmp_path: Path, skinned: bool
) -> None:
    pytest.importorskip("pxr", reason="USD export needs usd-core")
    from pxr import Usd, UsdGeom, UsdShade

    from ecs_tentacles.export.skinned_usd import write_skinned_usd
    from ecs_tentacles.export.usd import write_usd

    path = tmp_path / "take.usda"
    (write_skinned_usd if skinned else write_usd)(terrain_take, path)
    assert usd_problems(path) == []
    stage = Usd.Stage.Open(str(path))
    for label, name in (("surface", "terrain"), ("obstacles", "obstacles")):
        prim = stage.GetPrimAtPath(f"/World/terrain/{label}")
        mesh = dict(terrain_take.ground_meshes())[name]
        assert prim.IsA(UsdGeom.Mesh)
        assert len(UsdGeom.Mesh(prim).GetFaceVertexCountsAttr().Get()) == len(mesh.triangles)
        bound = UsdShade.MaterialBindingAPI(prim).ComputeBoundMaterial()[0]
        assert bound.GetPath() == f"/World/terrain/terrain_materials/{label}_material"
        # USD colours are linear: the sandbox's sand and rock, not paler
        shader = bound.ComputeSurfaceSource()[0]
        diffuse = np.array(shader.GetInput("diffuseColor").Get())
        np.testing.assert_allclose(diffuse, to_linear(COLOURS[name]), atol=1e-6)
        shown = np.array(UsdGeom.Mesh(prim).GetDisplayColorAttr().Get()[0])
        np.testing.assert_allclose(shown, to_linear(COLOURS[name]), atol=1e-6)


@pytest.mark.parametrize("skinned", [False, True], ids=["rigid", "skinned"])
def test_gltf_holds_the_terrain_node_and_validates(
    terrain_take: Take, tmp_path: Path, skinned: bool, gltf_validator: tuple[str, Path]
) -> None:
    path = tmp_path / "take.glb"
    if skinned:
        write_skinned_glb(terrain_take, path)
    else:
        write_glb(terrain_take, path)
    document, _ = read_glb(path.read_bytes())
    nodes = {node["name"]: node for node in document["nodes"]}
    assert {"terrain", "terrain/surface", "terrain/obstacles"} <= set(nodes)
    surface = document["meshes"][nodes["terrain/surface"]["mesh"]]["primitives"][0]
    indices = document["accessors"][surface["indices"]]
    assert indices["count"] == 3 * 2 * 16 * 16 and indices["componentType"] == 5125
    report = khronos_report(path, gltf_validator)
    assert (report["issues"]["numErrors"], report["issues"]["numWarnings"]) == (0, 0)


@pytest.mark.parametrize("skinned", [False, True], ids=["rigid", "skinned"])
def test_gltf_ground_materials_are_the_sandbox_colours_in_linear_light(
    terrain_take: Take, tmp_path: Path, skinned: bool
) -> None:
    """glTF's baseColorFactor is linear: written as the sandbox's display values, the
    sand and rock came out paler in every importer than the sandbox drew them."""
    path = tmp_path / "take.glb"
    (write_skinned_glb if skinned else write_glb)(terrain_take, path)
    document, _ = read_glb(path.read_bytes())
    nodes = {node["name"]: node for node in document["nodes"]}
    for label, name in (("surface", "terrain"), ("obstacles", "obstacles")):
        primitive = document["meshes"][nodes[f"terrain/{label}"]["mesh"]]["primitives"][0]
        factor = document["materials"][primitive["material"]]["pbrMetallicRoughness"]
        np.testing.assert_allclose(
            factor["baseColorFactor"], [*to_linear(COLOURS[name]), 1.0], atol=1e-6
        )


def test_a_take_from_before_meshes_carried_their_colour_exports_in_the_old_colours(
    terrain_take: Take, tmp_path: Path
) -> None:
    from ecs_tentacles.export.ground import linear_colour
    from ecs_tentacles.skin.colours import to_linear

    terrain_take.save(tmp_path / "t.npz")
    header = json.loads(json.dumps(terrain_take.header))
    for mesh in header["ground"]["meshes"]:
        del mesh["rgb"]  # as written before the colour was in the take
    text = json.dumps(header).encode()
    _rewrite(tmp_path / "t.npz", tmp_path / "old.npz", {"header": np.frombuffer(text, np.uint8)})
    old = Take.load(tmp_path / "old.npz")
    assert old.ground_colours() == {}
    for name in ("terrain", "obstacles"):
        np.testing.assert_allclose(linear_colour(old, name), to_linear(COLOURS[name]))
