"""Each creature's material carries its sandbox colour (`ecs_tentacles.skin.colours`) in the
four exports, and suckers and goals are locators only when asked for (skinned) or unless
left out (rigid)."""

from __future__ import annotations

from collections.abc import Iterator
from io import BytesIO
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from ecs_tentacles.cli import main
from ecs_tentacles.export.gltf import read_glb, write_glb
from ecs_tentacles.export.skinned_gltf import write_skinned_glb
from ecs_tentacles.skin.colours import creature_colour, look_in_world, to_linear
from ecs_tentacles.take import Take
from ecs_tentacles.world import World
from tests.export.conftest import khronos_report, record

NAMES = ["red", "green", "blue"]
SCENE: dict[str, Any] = {
    "version": 1,
    "name": "three",
    "seed": 2,
    "creatures": [
        {
            "name": name,
            "position": [2.0 * k, 0.0],
            "tentacles": {"count": 3, "links": 4},
            "goals": [{"position": [2.0 * k, 1.0], "radius": 0.2}],
        }
        for k, name in enumerate(NAMES)
    ],
}


def _sandbox_colours() -> dict[str, np.ndarray]:
    """Each creature's colour as the sandbox draws it (its default, natural palette)."""
    world = World.from_scene(SCENE)
    try:
        entities = [world.creature(name) for name in NAMES]
        return {
            name: creature_colour(look_in_world(world, entity, k))
            for k, (name, entity) in enumerate(zip(NAMES, entities, strict=True))
        }
    finally:
        world.close()


COLOURS = _sandbox_colours()


@pytest.fixture(scope="module")
def three() -> Iterator[Take]:
    """Three creatures, 6 frames."""
    world, system = record(SCENE, 6)
    yield system.take()
    world.close()


def _glb(path: Path) -> dict[str, Any]:
    document, binary = read_glb(path.read_bytes())
    document["binary"] = binary
    return document


def _mesh_materials(document: dict[str, Any]) -> dict[str, set[str]]:
    """The material names each node's mesh uses, by node name."""
    materials = [m["name"] for m in document["materials"]]
    meshes = document["meshes"]
    return {
        node["name"]: {materials[p["material"]] for p in meshes[node["mesh"]]["primitives"]}
        for node in document["nodes"]
        if "mesh" in node
    }


def test_the_rigid_glb_gives_each_creatures_bodies_its_colour(three: Take, tmp_path: Path) -> None:
    write_glb(three, tmp_path / "three.glb")
    document = _glb(tmp_path / "three.glb")
    by_name = {m["name"]: m for m in document["materials"]}
    assert set(by_name) == {f"{name}_material" for name in NAMES}
    for name in NAMES:
        factor = by_name[f"{name}_material"]["pbrMetallicRoughness"]["baseColorFactor"]
        np.testing.assert_allclose(factor, [*to_linear(COLOURS[name]), 1.0], atol=1e-6)
    used = _mesh_materials(document)
    bodies = [b["name"].split("/", 1)[0] for b in three.header["bodies"]]
    assert len(used) == len(bodies)  # every body has a mesh, none else
    for node, materials in used.items():
        assert materials == {f"{node.split('_', 1)[0]}_material"}, node


def test_the_skinned_glb_textures_each_creature_in_its_colour(three: Take, tmp_path: Path) -> None:
    from PIL import Image

    write_skinned_glb(three, tmp_path / "three.glb")
    document = _glb(tmp_path / "three.glb")
    assert _mesh_materials(document) == {f"{n}_skin": {f"{n}_material"} for n in NAMES}
    for material in document["materials"]:
        texture = document["textures"][
            material["pbrMetallicRoughness"]["baseColorTexture"]["index"]
        ]
        view = document["bufferViews"][document["images"][texture["source"]]["bufferView"]]
        start = view["byteOffset"]
        png = document["binary"][start : start + view["byteLength"]]
        pixels = np.asarray(Image.open(BytesIO(png)), dtype=np.float64) / 255
        top = pixels[:, : pixels.shape[1] // 2].reshape(-1, 3).mean(axis=0) / 0.9  # rings: 0.9
        name = material["name"].removesuffix("_material")
        np.testing.assert_allclose(top, COLOURS[name], atol=0.01)


def _usd_colours(path: Path) -> dict[str, tuple[str, np.ndarray]]:
    """Every Gprim's bound material and its diffuse colour, by prim name."""
    from pxr import Usd, UsdGeom, UsdShade

    stage = Usd.Stage.Open(str(path))
    out = {}
    for prim in stage.Traverse():
        if not prim.IsA(UsdGeom.Gprim) or prim.GetPath().pathString.startswith("/World/terrain"):
            continue
        material, _ = UsdShade.MaterialBindingAPI(prim).ComputeBoundMaterial()
        assert material, f"{prim.GetPath()} has no material"
        shader = material.ComputeSurfaceSource()[0]
        assert shader.GetIdAttr().Get() == "UsdPreviewSurface"
        colour = np.array(shader.GetInput("diffuseColor").Get())
        out[prim.GetName()] = (material.GetPath().pathString, colour)
    return out


@pytest.mark.parametrize("form", ["rigid", "skinned"])
def test_usd_binds_each_creature_to_a_material_of_its_colour(
    three: Take, tmp_path: Path, form: str
) -> None:
    pytest.importorskip("pxr", reason="USD export needs usd-core")
    from ecs_tentacles.export.skinned_usd import write_skinned_usd
    from ecs_tentacles.export.usd import write_usd

    path = tmp_path / "three.usda"
    if form == "rigid":
        write_usd(three, path)
    else:
        write_skinned_usd(three, path)
    found = _usd_colours(path)
    expected = len(three.header["bodies"]) if form == "rigid" else len(NAMES)
    assert len(found) == expected  # capsules and mantles, or one skin each
    for prim, (material, colour) in found.items():
        name = prim.split("_", 1)[0]
        assert material == f"/World/materials/{name}_material", prim
        np.testing.assert_allclose(colour, to_linear(COLOURS[name]), atol=1e-6)


def _glb_locators(path: Path) -> list[str]:
    names = [n["name"] for n in _glb(path)["nodes"]]
    return sorted(n for n in names if "_sucker" in n or "_goal" in n)


def _usd_locators(path: Path) -> list[str]:
    from pxr import Usd

    stage = Usd.Stage.Open(str(path))
    names = [prim.GetName() for prim in stage.Traverse()]
    return sorted(n for n in names if "_sucker" in n or "_goal" in n)


@pytest.mark.parametrize("suffix", [".glb", ".usda"])
def test_locators_only_with_the_option_when_skinned_and_unless_left_out_when_rigid(
    three: Take, tmp_path: Path, suffix: str
) -> None:
    if suffix != ".glb":
        pytest.importorskip("pxr", reason="USD export needs usd-core")
    take = tmp_path / "three.npz"
    three.save(take)
    suckers, creatures = len(three.header["suckers"]), len(NAMES)
    assert suckers == 3 * creatures  # a tip sucker per tentacle
    # a node per sucker, and per creature a goal and its folder <c>_goals (USD's skinned
    # form keeps its suckers in a folder <c>_suckers too)
    located = suckers + 2 * creatures
    expected = {
        "": 0,
        "--locators": located + (creatures if suffix == ".usda" else 0),
        "--rigid": located,
        "--rigid --no-locators": 0,
    }
    locators = _glb_locators if suffix == ".glb" else _usd_locators
    for k, options in enumerate(expected):
        out = tmp_path / f"three{k}{suffix}"
        assert main(["export", str(take), "--out", str(out), "--quiet", *options.split()]) == 0
        found = locators(out)
        assert len(found) == len(set(found)) == expected[options], options
        assert {n.split("_", 1)[0] for n in found} <= set(NAMES)


def test_a_skinned_glb_with_locators_passes_the_khronos_validator(
    three: Take, tmp_path: Path, gltf_validator: tuple[str, Path]
) -> None:
    path = tmp_path / "three.glb"
    write_skinned_glb(three, path, locators=True)
    report = khronos_report(path, gltf_validator)
    assert report["issues"]["messages"] == []
    assert (report["issues"]["numErrors"], report["issues"]["numWarnings"]) == (0, 0)


@pytest.mark.parametrize("form", ["rigid", "skinned"])
def test_a_glb_sucker_locator_sits_at_its_sucker(three: Take, form: str) -> None:
    """At frame 0 (the bind pose) the sucker node, through its parent's transform, is at
    the sucker's point of the take, turned y-up."""
    from ecs_tentacles.export.gltf import build_gltf, to_y_up_points
    from ecs_tentacles.export.skinned_gltf import build_skinned_gltf
    from ecs_tentacles.numeric.quaternions import quat_rotate
    from ecs_tentacles.skin.skeleton import quat_matrix

    if form == "rigid":
        document, _ = build_gltf(three, locators=True)
    else:
        document, _, _ = build_skinned_gltf(three, locators=True)
    nodes = document["nodes"]
    parent_of = {c: i for i, n in enumerate(nodes) for c in n.get("children", [])}

    def world(index: int) -> np.ndarray:
        node, matrix = nodes[index], np.eye(4)
        x, y, z, w = node.get("rotation", [0.0, 0.0, 0.0, 1.0])
        matrix[:3, :3] = quat_matrix(np.array([w, x, y, z]))
        matrix[:3, 3] = node.get("translation", [0.0, 0.0, 0.0])
        return world(parent_of[index]) @ matrix if index in parent_of else matrix

    by_name = {n["name"]: i for i, n in enumerate(nodes)}
    for sucker in three.header["suckers"]:
        leaf = "_".join(sucker["name"].split("/")[:1] + sucker["name"].split("/")[2:])
        body = sucker["body"]
        point = three.pos[0, body] + quat_rotate(three.quat[0, body], np.array(sucker["offset"]))
        found = world(by_name[leaf])[:3, 3]
        np.testing.assert_allclose(found, to_y_up_points(point), atol=1e-5)
        assert nodes[by_name[leaf]]["extras"] == {"ecs:locator": "sucker"}
