"""Every prim of a USD export has a name of its own in the file (`ecs_tentacles.export.names`):
importers that keep one namespace for the objects they make (meshes, materials,
skeletons, xforms, the empties of scopes) would otherwise rename the second one
(`octopus_skin.001`). Bundled scenes exported in every USD form, then checked as the
USD export tests check a file."""

from __future__ import annotations

import json
from collections import Counter
from pathlib import Path

import pytest

from ecs_tentacles.cli import main
from ecs_tentacles.export.usd_validation import usd_problems

pytest.importorskip("pxr", reason="USD export needs usd-core (the usd / dev extras)")
from pxr import Usd

# rocky_shore: six creatures with goals on a heightfield with rocks (the ground's meshes
# and materials); hedgehog_octopus: a furred creature (a curves track); named_as_folders:
# creatures called as the folders the export makes beside them (their root prims would
# be taken over by the scopes of materials and the ground)
SCENES = ("rocky_shore", "hedgehog_octopus", "named_as_folders")
NAMED_AS_FOLDERS = {
    "version": 1,
    "terrain": {
        "heightfield": {"size": [8, 8], "resolution": 9, "height": 0.2, "noise": {"seed": 2}},
        "obstacles": [{"shape": "box", "position": [0, 2.5, 0.2], "size": [0.4, 0.4, 0.4]}],
    },
    "creatures": [
        {"name": name, "position": [2.0 * k - 2.0, -1.0], "tentacles": {"count": 3, "links": 3}}
        for k, name in enumerate(["materials", "terrain", "octo"])
    ],
}
FORMS = {
    "skinned.usda": ["--locators"],
    "skinned.usdc": ["--keys", "reduced"],
    "rigid.usda": ["--rigid"],
    "rigid.usdc": ["--rigid", "--no-locators"],
}


@pytest.fixture(scope="module")
def takes(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    folder = tmp_path_factory.mktemp("takes")
    out = {}
    (folder / "named_as_folders.json").write_text(json.dumps(NAMED_AS_FOLDERS))
    for scene in SCENES:
        source = str(folder / f"{scene}.json") if scene == "named_as_folders" else scene
        out[scene] = folder / f"{scene}.npz"
        assert main(["bake", source, "--seconds", "0.05", "--out", str(out[scene]), "--quiet"]) == 0
    return out


@pytest.mark.parametrize("form", sorted(FORMS))
@pytest.mark.parametrize("scene", SCENES)
def test_every_prim_name_is_unique_in_a_usd_export(
    takes: dict[str, Path], tmp_path: Path, scene: str, form: str
) -> None:
    path = tmp_path / f"{scene}_{form}"
    assert main(["export", str(takes[scene]), "--out", str(path), "--quiet", *FORMS[form]]) == 0
    stage = Usd.Stage.Open(str(path))
    prims = list(stage.Traverse())
    kinds = Counter(prim.GetTypeName() for prim in prims)
    assert kinds["Material"] >= 1 and kinds["Mesh" if "skinned" in form else "Capsule"] >= 1
    if scene == "rocky_shore":
        assert stage.GetPrimAtPath("/World/terrain/surface").GetTypeName() == "Mesh"
    if scene == "named_as_folders":  # each creature's root is its own, with its parts
        root = "SkelRoot" if "skinned" in form else "Xform"
        for name in ("materials", "terrain", "octo"):
            assert stage.GetPrimAtPath(f"/World/{name}").GetTypeName() == root, name
        assert stage.GetPrimAtPath("/World/terrain_ground/surface").GetTypeName() == "Mesh"
        assert stage.GetPrimAtPath("/World/materials_1").GetTypeName() == "Scope"
    repeated = Counter(prim.GetName() for prim in prims) - Counter(set(p.GetName() for p in prims))
    where = {n: [str(p.GetPath()) for p in prims if p.GetName() == n] for n in repeated}
    assert where == {}
    assert usd_problems(path) == []
