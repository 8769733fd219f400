"""tools/blender_import.py in Blender (bpy 5.0.1): exports open at their own frame rate
and range, each creature in a material of its sandbox colour, names as written, and no
objects an artist did not ask for (locators only with --locators, no bone shapes, no
empties for material scopes)."""

from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from ecs_tentacles.cli import main
from ecs_tentacles.export.materials import take_colours
from ecs_tentacles.skin.colours import to_linear
from ecs_tentacles.take import Take
from tests.conftest import baked

BLENDER = os.environ.get("ECS_TENTACLES_BLENDER_PYTHON", "")
TOOL = Path(__file__).resolve().parents[2] / "tools" / "blender_import.py"
READ = """
import json, sys, bpy
bpy.ops.wm.open_mainfile(filepath=sys.argv[1])
scene = bpy.context.scene
meshes = [o for o in bpy.data.objects if o.type == "MESH" and o.data.materials]
print(json.dumps({
    "fps": scene.render.fps / scene.render.fps_base,
    "range": [scene.frame_start, scene.frame_end],
    "actions": [list(a.frame_range) for a in bpy.data.actions],
    "materials": sorted({m.name for o in meshes for m in o.data.materials}),
}))
"""

pytestmark = pytest.mark.skipif(
    not Path(BLENDER).is_file(),
    reason="set ECS_TENTACLES_BLENDER_PYTHON to a Python with bpy (CI installs bpy==5.0.1)",
)


def _tool(take: Path, blend: Path, *options: str) -> str:
    """`tools/blender_import.py TAKE --out BLEND OPTIONS` in Blender's Python: what it
    printed (it must succeed within 3 minutes)."""
    done = subprocess.run(
        [BLENDER, str(TOOL), str(take), "--out", str(blend), *options],
        capture_output=True, text=True, timeout=180,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    return done.stdout


@pytest.mark.parametrize("suffix", [".usdc", ".glb"])
def test_an_export_opens_in_blender_at_its_rate_and_range(tmp_path: Path, suffix: str) -> None:
    take = tmp_path / f"take{suffix}"
    argv = ["bake", "octopus", "--seconds", "1", "--fps", "30", "--out", str(take), "--quiet"]
    assert main(argv) == 0
    blend = tmp_path / "take.blend"
    said = _tool(take, blend)
    assert said.splitlines()[-1] == f"{blend}: {take.name} at 30 fps, frames 0-30"
    read = subprocess.run(
        [BLENDER, "-c", READ, str(blend)], capture_output=True, text=True, timeout=120
    )
    found = json.loads(read.stdout.splitlines()[-1])
    assert found["fps"] == 30 and found["range"] == [0, 30]  # 31 frames, 1 s at 30 fps
    assert found["actions"] and all(a == [0.0, 30.0] for a in found["actions"])
    assert found["materials"] == ["octopus_material"]  # USD imports it too, not grey


GROUND = """
import json, sys, bpy
bpy.ops.wm.open_mainfile(filepath=sys.argv[1])
found = {o.name: [m.name for m in o.data.materials] for o in bpy.data.objects
         if o.type == "MESH" and ("surface" in o.name or "obstacles" in o.name)}
print(json.dumps(found))
"""


@pytest.mark.parametrize("suffix", [".usdc", ".glb"])
def test_the_terrain_comes_into_blender_as_meshes_with_materials(
    tmp_path: Path, suffix: str
) -> None:
    take = tmp_path / f"shore{suffix}"
    argv = ["bake", "rocky_shore", "--seconds", "0.2", "--fps", "30", "--out", str(take)]
    assert main([*argv, "--quiet"]) == 0
    blend = tmp_path / "shore.blend"
    found = _imported(take, blend, GROUND)
    # USD keeps the prim names (surface, obstacles); glTF the node names (terrain/...)
    surface = next(name for name in found if name.endswith("surface"))
    obstacles = next(name for name in found if name.endswith("obstacles"))
    assert found[surface] and found[obstacles]  # each with its material, not grey


NAMES = """
import json, re, sys, bpy
bpy.ops.wm.open_mainfile(filepath=sys.argv[1])
print(json.dumps({
    "suffixed": [o.name for o in bpy.data.objects if re.search(r"[.][0-9]{3}$", o.name)
                 and not o.name.startswith("Icosphere")],  # the glTF importer's bone shapes
    "armatures": sorted(o.name for o in bpy.data.objects if o.type == "ARMATURE"),
    "meshes": sorted(o.name for o in bpy.data.objects if o.type == "MESH"),
    "actions": sorted(a.name for a in bpy.data.actions),
}))
"""


def test_four_creatures_import_with_their_own_names_in_usd_and_glb(tmp_path: Path) -> None:
    """No `.001` suffixes (every prim and node is named uniquely, after its creature), and
    the same armature, mesh and action names from USD and from glTF."""
    found = {}
    for suffix in (".usdc", ".glb"):
        take = tmp_path / f"four{suffix}"
        argv = ["bake", "thesis_four_by_six", "--seconds", "0.2", "--fps", "30"]
        assert main([*argv, "--out", str(take), "--quiet"]) == 0
        blend = tmp_path / f"four{suffix}.blend"
        found[suffix] = _imported(take, blend, NAMES)
        assert found[suffix]["suffixed"] == []
    usd, glb = found[".usdc"], found[".glb"]
    assert usd["armatures"] == glb["armatures"] == [f"creature_{i}_skeleton" for i in range(4)]
    assert usd["actions"] == [f"creature_{i}_animation" for i in range(4)]
    assert glb["actions"] == ["take"]  # one clip driving every creature (a slot each)
    assert {f"creature_{i}_skin" for i in range(4)} <= set(usd["meshes"]) & set(glb["meshes"])


def _imported(take: Path, blend: Path, script: str) -> dict[str, Any]:
    """Import `take` with the tool into `blend`, then what `script` prints of it (JSON)."""
    _tool(take, blend)
    read = subprocess.run(
        [BLENDER, "-c", script, str(blend)], capture_output=True, text=True, timeout=120
    )
    found: dict[str, Any] = json.loads(read.stdout.splitlines()[-1])
    return found


PLAYING = """
import json, sys, bpy
bpy.ops.wm.open_mainfile(filepath=sys.argv[1])
scene = bpy.context.scene
def poses(frame):
    scene.frame_set(frame)
    return {o.name: [list(map(list, b.matrix)) for b in o.pose.bones]
            for o in bpy.data.objects if o.type == "ARMATURE"}
first, later = poses(0), poses(20)
print(json.dumps({
    o.name: {
        "action": bool(o.animation_data and o.animation_data.action),
        "moved": max(abs(x - y) for a, b in zip(first[o.name], later[o.name])
                     for ra, rb in zip(a, b) for x, y in zip(ra, rb)),
    }
    for o in bpy.data.objects if o.type == "ARMATURE"
}))
"""


@pytest.mark.parametrize("suffix", [".usdc", ".glb"])
def test_every_creature_plays_in_blender(tmp_path: Path, suffix: str) -> None:
    """Every armature has an active action and its bones move between two frames (a glb
    with one animation per creature played one creature: Blender stashes all but the
    first animation in muted NLA tracks)."""
    take = tmp_path / f"four{suffix}"
    argv = ["bake", "thesis_four_by_six", "--seconds", "1", "--fps", "30"]
    assert main([*argv, "--out", str(take), "--quiet"]) == 0
    found = _imported(take, tmp_path / "four.blend", PLAYING)
    assert sorted(found) == [f"creature_{i}_skeleton" for i in range(4)]
    for name, armature in found.items():
        assert armature["action"], f"{name} has no active action"
        assert armature["moved"] > 0.01, f"{name} does not move"


@pytest.mark.parametrize("suffix", [".usdc", ".glb"])
def test_every_creature_of_a_crowd_on_all_three_tiers_plays_in_blender(
    tmp_path: Path, suffix: str
) -> None:
    """1 full, 2 reduced and 3 replayed creatures (level of detail): all six come in as
    armatures with an active action, and every one moves."""
    from tests.cli.test_measure import lod_crowd

    scene = tmp_path / "crowd.json"
    scene.write_text(json.dumps(lod_crowd(6)))
    take = tmp_path / f"crowd{suffix}"
    argv = ["bake", str(scene), "--seconds", "1", "--fps", "30"]
    assert main([*argv, "--out", str(take), "--quiet"]) == 0
    found = _imported(take, tmp_path / "crowd.blend", PLAYING)
    assert len(found) == 6
    for name, armature in found.items():
        assert armature["action"], f"{name} has no active action"
        assert armature["moved"] > 0.01, f"{name} does not move"


CROWD = """
import json, sys, bpy
bpy.ops.wm.open_mainfile(filepath=sys.argv[1])
scene = bpy.context.scene
found = {}
for frame in (0, 1, 24, 48):
    scene.frame_set(frame)
    for o in bpy.data.objects:
        if o.type == "ARMATURE":
            found.setdefault(o.name, []).append(list(o.matrix_world @ o.pose.bones[0].head))
print(json.dumps(found))
"""


def test_a_crowd_sharing_clip_animations_plays_where_the_take_has_it(tmp_path: Path) -> None:
    """A level-of-detail crowd's take (15 of 16 creatures replay one shared clip animation
    from frame 1 in the USD, each on a skeleton of its own stretch) comes into Blender
    with every skeleton posed where the take has the creature on the frames USD shows
    it (frame 0 on its own skeleton, the others on its stretch's), within 1 cm at four
    frames, and every creature moving. Blender's importer (5.0.1) does not bring USD's
    animated visibility along: both skeletons of a replayed creature stay shown."""
    from ecs_tentacles.take.stream import open_take
    from tests.export.conftest import replay_crowd_take

    take = replay_crowd_take(tmp_path)
    usd = tmp_path / "crowd16.usdc"
    assert main(["export", str(take), "--out", str(usd), "--quiet"]) == 0
    found = _imported(usd, tmp_path / "crowd16.blend", CROWD)
    with open_take(take) as source:
        header = source.header
        chunk = next(iter(source.chunks()))[1]
        replayed = [len(source.segments(c)) == 1 for c in range(len(header["creatures"]))]
    assert sum(replayed) == 15
    assert len(found) == 16 + 15  # a skeleton each, and one per replayed stretch
    for entry, replays in zip(header["creatures"], replayed, strict=True):
        name = entry["name"]
        mantles = np.array(found[f"{name}_skeleton"])
        if replays:  # frame 0 on its own skeleton, the others on its stretch's
            stretch = np.array(found[f"{name}_replay0_skeleton"])
            mantles = np.concatenate([mantles[:1], stretch[1:]])
        expected = chunk.pos[[0, 1, 24, 48], entry["mantle"]]
        assert np.linalg.norm(mantles - expected, axis=1).max() < 0.01, name
        assert np.linalg.norm(mantles[-1] - mantles[0]) > 0.05, name  # it moved


LOOKS = """
import json, sys, bpy
bpy.ops.wm.open_mainfile(filepath=sys.argv[1])
def colour(material):
    nodes = material.node_tree.nodes
    image = next((n.image for n in nodes if n.type == "TEX_IMAGE"), None)
    if image is not None:  # a texture: its mean over the half away from the underside
        w, h = image.size
        px = list(image.pixels)
        rows = [px[4 * (y * w + x): 4 * (y * w + x) + 3] for y in range(h) for x in range(w // 2)]
        return ["texture", [sum(r[i] for r in rows) / len(rows) for i in range(3)]]
    bsdf = next(n for n in nodes if n.type == "BSDF_PRINCIPLED")
    return ["factor", list(bsdf.inputs["Base Color"].default_value)[:3]]
print(json.dumps({
    "all_objects": sorted(o.name for o in bpy.data.objects),
    "meshes": {o.name: [m.name for m in o.data.materials]
               for o in bpy.data.objects if o.type == "MESH"},
    "colours": {m.name: colour(m) for m in bpy.data.materials},
}))
"""
FOUR = [f"creature_{i}" for i in range(4)]


@pytest.fixture(scope="module")
def four_take(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """thesis_four_by_six, 0.5 s at 30 fps: four creatures of six tentacles, a goal each."""
    return baked("thesis_four_by_six", tmp_path_factory.mktemp("four") / "four.npz", 0.5)


def _report(take: Path, blend: Path) -> tuple[dict[str, Any], dict[str, Any]]:
    """Import `take` with `--report`: (the tool's report, what LOOKS reads back)."""
    report: dict[str, Any] = json.loads(_tool(take, blend, "--report").splitlines()[-2])
    read = subprocess.run(
        [BLENDER, "-c", LOOKS, str(blend)], capture_output=True, text=True, timeout=120
    )
    return report, json.loads(read.stdout.splitlines()[-1])


@pytest.mark.parametrize("suffix", [".glb", ".usdc"])
def test_a_skinned_import_holds_what_the_artist_animates_and_nothing_else(
    four_take: Path, tmp_path: Path, suffix: str
) -> None:
    """Four armatures that animate, four skins each in its creature's sandbox colour, the
    World (and in USD each creature's SkelRoot) as the only empties: no locators unless
    asked for, no `materials` scope empties, no Icosphere bone shapes."""
    out = tmp_path / f"four{suffix}"
    assert main(["export", str(four_take), "--out", str(out), "--quiet"]) == 0
    report, looks = _report(out, tmp_path / "four.blend")
    roots = FOUR if suffix == ".usdc" else []
    assert report["empties"] == sorted(["World", *roots])
    assert report["by_type"] == {"ARMATURE": 4, "EMPTY": 1 + len(roots), "MESH": 4}
    assert (report["armatures"], report["animating"], report["outside_scene"]) == (4, 4, [])
    assert not [n for n in looks["all_objects"] if "Icosphere" in n or "materials" in n]
    assert looks["meshes"] == {f"{c}_skin": [f"{c}_material"] for c in FOUR}
    sandbox = take_colours(Take.load(four_take))  # the sandbox's default palette
    for c in FOUR:
        srgb = sandbox[c]
        kind, colour = looks["colours"][f"{c}_material"]
        if kind == "texture":  # sRGB bytes as Blender reads them; rings: 0.9 on average
            np.testing.assert_allclose(np.array(colour) / 0.9, srgb, atol=0.02)
        else:
            np.testing.assert_allclose(colour, to_linear(srgb), atol=1e-4)


@pytest.mark.parametrize("suffix", [".glb", ".usdc"])
def test_locators_come_in_as_empties_only_with_the_option(
    four_take: Path, tmp_path: Path, suffix: str
) -> None:
    out = tmp_path / f"four{suffix}"
    argv = ["export", str(four_take), "--out", str(out), "--quiet", "--locators"]
    assert main(argv) == 0
    report, _ = _report(out, tmp_path / "four.blend")
    suckers = [e for e in report["empties"] if "_sucker" in e and not e.endswith("_suckers")]
    goals = [e for e in report["empties"] if e.endswith("_goal0")]
    assert (len(suckers), len(goals)) == (4 * 6, 4)  # a tip sucker per tentacle, a goal each
    assert report["animating"] == 4


def test_a_rigid_usd_gives_every_capsule_its_creatures_material(
    four_take: Path, tmp_path: Path
) -> None:
    """Blender's USD importer binds no material to Capsule and Cylinder prims: the tool
    binds each to its creature's."""
    out = tmp_path / "rigid.usdc"
    assert main(["export", str(four_take), "--out", str(out), "--quiet", "--rigid"]) == 0
    report, looks = _report(out, tmp_path / "rigid.blend")
    assert report["by_type"]["MESH"] == 4 * (1 + 6 * 10)
    for mesh, materials in looks["meshes"].items():
        assert materials == [f"{mesh.split('_')[0]}_{mesh.split('_')[1]}_material"], mesh
    assert sorted(looks["colours"]) == [f"{c}_material" for c in FOUR]


SKY_SRGB = (206, 219, 231)  # the tool's sky, (0.62, 0.71, 0.80) linear, as 8-bit sRGB


@pytest.fixture(scope="module")
def shore_take(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """rocky_shore, 0.4 s at 30 fps: three creatures on each side of the shore."""
    return baked("rocky_shore", tmp_path_factory.mktemp("shore") / "shore.npz", 0.4)


@pytest.mark.parametrize(
    ("suffix", "size"), [(".glb", (960, 540)), (".usdc", (480, 270))]
)  # the default size, and `--size` (a quarter of the pixels: 3 s less to render)
def test_a_still_of_the_import_shows_every_creature_in_its_colour_on_the_ground(
    shore_take: Path, tmp_path: Path, suffix: str, size: tuple[int, int]
) -> None:
    """`--render`: a PNG of the default 960x540 or of `--size`, mostly not sky, with the
    sandbox's creature colours on the left and on the right (rocky_shore has three
    creatures on each side) and the ground's colour, written whole."""
    from PIL import Image

    from ecs_tentacles.terrain.ground_meshes import COLOURS

    take = shore_take
    out = tmp_path / f"shore{suffix}"
    assert main(["export", str(take), "--out", str(out), "--quiet"]) == 0
    png = tmp_path / "shot.png"
    sized = [] if size == (960, 540) else ["--size", f"{size[0]}x{size[1]}"]
    done = subprocess.run(
        [BLENDER, str(TOOL), str(out), "--render", str(png), "--frame", "6", *sized],
        capture_output=True,
        text=True,
        timeout=180,
    )
    assert done.returncode == 0, done.stderr
    said = f"{png}: {size[0]}x{size[1]}, frame 6, 6 creature meshes"
    assert done.stdout.splitlines()[-2].startswith(said)
    assert [p.name for p in tmp_path.iterdir() if p.suffix == ".png"] == ["shot.png"]
    with Image.open(png) as image:
        assert image.size == size
        pixels = np.asarray(image.convert("RGB")).astype(float)
    sky = np.abs(pixels - SKY_SRGB).max(axis=2) <= 3
    assert 0.05 < sky.mean() < 0.5  # a sky above the ground, the picture mostly scene

    def near(srgb: np.ndarray) -> np.ndarray:
        """Pixels of `srgb`'s hue, however lit (chromaticity within 0.03)."""
        chroma = pixels / np.maximum(pixels.sum(axis=2, keepdims=True), 1.0)
        return np.abs(chroma - srgb / srgb.sum()).max(axis=2) < 0.03

    creatures = np.zeros(pixels.shape[:2], bool)
    for colour in take_colours(Take.load(take)).values():
        creatures |= near(colour)
    third = pixels.shape[1] // 3
    left, right = creatures[:, :third].sum(), creatures[:, -third:].sum()
    least = 1000 * size[0] * size[1] / (960 * 540)  # pixels of creature at 960x540: 1,000
    assert left > least and right > least, (left, right)  # west's three, east's three
    assert near(np.asarray(COLOURS["terrain"], float)).mean() > 0.25  # the sand
