"""The add-on in Blender (bpy 5.0.1): a small crowd comes in as armatures and skinned
meshes sharing data per body plan, every creature moves, its joints where the take has
them; the scene plays at the take's rate over its range; a bad file is one line."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import numpy as np
import pytest

from ecs_tentacles.cli import main
from ecs_tentacles.creator.crowd import crowd_scene
from ecs_tentacles.export.materials import take_colours
from ecs_tentacles.skin.colours import to_linear
from ecs_tentacles.take import Take
from ecs_tentacles.take.stream import open_take
from tests.blender_addon.conftest import BLENDER, needs_blender, run
from tests.export.broken_takes import BROKEN_TAKES
from tests.export.conftest import come_and_go_take

pytestmark = needs_blender

READ = """
scene = bpy.context.scene
armatures = sorted((o for o in scene.objects if o.type == "ARMATURE"), key=lambda o: o.name)
joints = {}
for frame in json.loads(sys.argv[2]):
    scene.frame_set(frame)
    depsgraph = bpy.context.evaluated_depsgraph_get()
    for o in armatures:
        posed = o.evaluated_get(depsgraph)
        world = posed.matrix_world
        joints.setdefault(o.name, []).append(
            [list(world @ b.head) for b in posed.pose.bones])
def strips(o):
    return {t.name: [[s.action.name, s.frame_start, s.frame_end] for s in t.strips]
            for t in o.animation_data.nla_tracks}
skins = {o.name: o for o in scene.objects if o.type == "MESH"}
print(json.dumps({
    "fps": scene.render.fps / scene.render.fps_base,
    "range": [scene.frame_start, scene.frame_end],
    "joints": joints,
    "bones": {o.name: [b.name for b in o.pose.bones] for o in armatures},
    "armature_data": {o.name: o.data.name for o in armatures},
    "mesh_data": {name: o.data.name for name, o in skins.items()},
    "deformed_by": {name: [m.object.name for m in o.modifiers if m.type == "ARMATURE"]
                    for name, o in skins.items()},
    "materials": {name: [s.link, s.material.name,
                         list(s.material.node_tree.nodes["Principled BSDF"]
                              .inputs["Base Color"].default_value)[:3]]
                  for name, o in skins.items() for s in o.material_slots},
    "active": {o.name: o.animation_data.action and o.animation_data.action.name
               for o in armatures},
    "tracks": {o.name: strips(o) for o in armatures},
    "skin_vertices": {name: len(o.data.vertices) for name, o in skins.items()},
    "users": {a.name: a.users for a in bpy.data.actions},
    "vertices": {m.name: len(m.vertices) for m in bpy.data.meshes},
}))
"""
IMPORT = "bpy.ops.import_scene.ecs_tentacles_take(filepath=sys.argv[1])" + READ
OPEN = "bpy.ops.wm.open_mainfile(filepath=sys.argv[1])" + READ
TOOL = Path(__file__).resolve().parents[2] / "tools" / "blender_import.py"


@pytest.fixture(scope="module")
def crowd_take(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Six creatures of one body plan spread wide, 1 s at 30 fps, with level-of-detail
    budgets that put them on all three tiers (1 full, 2 reduced, 3 replayed)."""
    folder = tmp_path_factory.mktemp("crowd")
    scene = crowd_scene(6, seed=2, spacing=4.0, uniform=True)
    scene["physics"] = {"lod": {"full": 1, "reduced": 2, "hold_seconds": 0,
                                "focus": {"center": [0.0, 0.0], "radius": 0.0}}}  # fmt: skip
    (folder / "crowd.json").write_text(json.dumps(scene))
    take = folder / "crowd.npz"
    argv = ["bake", str(folder / "crowd.json"), "--seconds", "1", "--fps", "30", "--quiet"]
    assert main([*argv, "--out", str(take)]) == 0
    return take


def joint_positions(take: Take) -> dict[str, np.ndarray]:
    """Each creature's joints (frames, J, 3) from the take's body poses: the mantle's
    centre, each link's base (its centre less half its length along its +x)."""
    out = {}
    bodies = take.header["bodies"]
    for creature in take.header["creatures"]:
        index = [creature["mantle"], *(i for chain in creature["tentacles"] for i in chain)]
        pos = take.pos[:, index].astype(np.float64)
        q = take.quat[:, index].astype(np.float64)
        w, x, y, z = np.moveaxis(q / np.linalg.norm(q, axis=-1, keepdims=True), -1, 0)
        ahead = np.stack([1 - 2 * (y * y + z * z), 2 * (x * y + w * z), 2 * (x * z - w * y)], -1)
        half = np.array([0.0] + [0.5 * bodies[i]["length"] for i in index[1:]])
        out[f"{creature['name']}_skeleton"] = pos - half[None, :, None] * ahead
    return out


def test_a_small_crowd_comes_in_sharing_data_per_body_plan_and_every_creature_moves(
    crowd_take: Path, blender_env: dict[str, str]
) -> None:
    take = Take.load(crowd_take)
    frames = [0, take.frames // 2, take.frames - 1]
    found = run(blender_env, IMPORT, str(crowd_take), json.dumps(frames))
    names = [c["name"] for c in take.header["creatures"]]
    skeletons = [f"{n}_skeleton" for n in names]
    assert found["fps"] == 30 and found["range"] == [0, take.frames - 1]
    assert sorted(found["joints"]) == sorted(skeletons)
    expected = joint_positions(take)
    for name in skeletons:
        joints = np.array(found["joints"][name])  # (3 frames, J, 3)
        assert found["bones"][name][:2] == ["mantle", "t0_link0"]
        np.testing.assert_allclose(joints[:, 0], expected[name][frames, 0], atol=0.01)  # mantle
        np.testing.assert_allclose(joints, expected[name][frames], atol=0.01)  # every joint
        moved = np.linalg.norm(joints[-1] - joints[0], axis=-1).max()
        assert moved > 0.02, f"{name} does not move ({moved:.4f} m)"
    # one body plan: one armature and one mesh for all six, each skin deformed by its own
    assert set(found["armature_data"].values()) == {"plan_skeleton"}
    assert set(found["mesh_data"].values()) == {"plan_skin"}
    assert list(found["vertices"]) == ["plan_skin"] and found["vertices"]["plan_skin"] > 1000
    assert found["deformed_by"] == {f"{n}_skin": [f"{n}_skeleton"] for n in names}
    colours = take_colours(take)
    for name, skeleton in zip(names, skeletons, strict=True):
        link, material, colour = found["materials"][f"{name}_skin"]
        assert (link, material) == ("OBJECT", f"{name}_material")  # the mesh is shared
        np.testing.assert_allclose(colour, to_linear(colours[name]), atol=1e-6)
        assert found["active"][skeleton] == f"{name}_root"


def test_replayed_creatures_share_one_action_per_clip_through_nla_strips(
    crowd_take: Path, blender_env: dict[str, str]
) -> None:
    """The crowd's replayed stretches (level of detail) are strips of one shared action
    per clip and kind, placed at their frames; a creature simulated at some frame has its
    own keys (`<c>_pose`, under the strips), one never simulated has none."""
    with open_take(crowd_take) as source:
        names = [c["name"] for c in source.header["creatures"]]
        stretches = {n: source.segments(c) for c, n in enumerate(names)}
        kind = source.replay_records()["replay_kind"]
    assert sum(map(len, stretches.values())) >= 3  # the crowd has replayed stretches
    found = run(blender_env, IMPORT, str(crowd_take), json.dumps([0]))
    kinds = ("idle", "crawl")
    for c, name in enumerate(names):
        tracks = found["tracks"][f"{name}_skeleton"]
        expected = [[f"clip{s.clip}_{kinds[s.kind]}", s.first] for s in stretches[name]]
        assert [[a, start] for a, start, _ in tracks.get("clips", [])] == expected, name
        simulated = bool((kind[:, c] < 0).any())
        assert ("physical" in tracks) == simulated, name
        if simulated:
            assert [a for a, _, _ in tracks["physical"]] == [f"{name}_pose"]
    shared = [s for strips in found["tracks"].values() for s in strips.get("clips", [])]
    for action in {a for a, _, _ in shared}:  # one action, used by every strip playing it
        assert found["users"][action] == sum(a == action for a, _, _ in shared) >= 2
    assert not [a for a in found["users"] if a.endswith("_pose") and a[:-5] not in names]


BAD = """
KINDS = ("objects", "meshes", "armatures", "materials", "actions", "collections")
before = {kind: len(getattr(bpy.data, kind)) for kind in KINDS}
try:
    bpy.ops.import_scene.ecs_tentacles_take(filepath=sys.argv[1])
    said = None
except RuntimeError as error:
    said = str(error)
after = {kind: len(getattr(bpy.data, kind)) for kind in KINDS}
print(json.dumps({"said": said, "made": [before, after]}))
"""


@pytest.mark.parametrize("case", ["truncated_file", "nan_position"])
def test_a_bad_file_is_one_line_and_makes_nothing(
    case: str, crowd_take: Path, blender_env: dict[str, str], tmp_path: Path
) -> None:
    """Refused when opened (a cut file) or half-way through (a NaN in the poses, found
    once the armatures and meshes are made: they are removed)."""
    bad = tmp_path / f"{case}.npz"
    BROKEN_TAKES[case](crowd_take, bad)
    found = run(blender_env, BAD, str(bad))
    said = found["said"]
    assert said is not None and "\n" not in said.strip(), said
    expected = {
        "truncated_file": "not a take file (not an npz archive: File is not a zip file)",
        "nan_position": "pos: nan at (1, 2, 0) is not a finite number within 1e+06 m",
    }
    assert said.strip() == f"Error: {bad}: {expected[case]}"
    assert found["made"][0] == found["made"][1]


def test_the_addon_shows_what_the_usd_import_shows(
    blender_env: dict[str, str], tmp_path: Path
) -> None:
    """thesis_four_by_six through the add-on and through today's USD import
    (`tools/blender_import.py`): the same armatures, bones and skin vertices, every
    joint within 1 mm at three frames, the same material colours."""
    take = tmp_path / "four.npz"
    argv = ["bake", "thesis_four_by_six", "--seconds", "0.5", "--fps", "30", "--quiet"]
    assert main([*argv, "--out", str(take)]) == 0
    usd = tmp_path / "four.usdc"
    assert main(["export", str(take), "--out", str(usd), "--quiet"]) == 0
    blend = tmp_path / "four.blend"
    done = subprocess.run([BLENDER, str(TOOL), str(usd), "--out", str(blend)],
                          capture_output=True, text=True, timeout=180, check=False)  # fmt: skip
    assert done.returncode == 0, done.stderr
    frames = json.dumps([0, 7, 15])
    through_usd = run(blender_env, OPEN, str(blend), frames)
    through_addon = run(blender_env, IMPORT, str(take), frames)
    assert sorted(through_addon["joints"]) == sorted(through_usd["joints"])
    assert len(through_addon["joints"]) == 4
    assert through_addon["bones"] == through_usd["bones"]
    assert through_addon["skin_vertices"] == through_usd["skin_vertices"]
    for name, joints in through_usd["joints"].items():
        np.testing.assert_allclose(through_addon["joints"][name], joints, atol=0.001)
    for name, (_, material, colour) in through_usd["materials"].items():
        assert through_addon["materials"][name][1] == material
        np.testing.assert_allclose(through_addon["materials"][name][2], colour, atol=1e-4)
    assert (through_addon["fps"], through_addon["range"]) == (
        through_usd["fps"],
        through_usd["range"],
    )


SHOWN = """
bpy.ops.import_scene.ecs_tentacles_take(filepath=sys.argv[1])
scene = bpy.context.scene
shown = {}
for frame in range(scene.frame_start, scene.frame_end + 1):
    scene.frame_set(frame)
    for o in scene.objects:
        if o.type == "MESH":
            shown.setdefault(o.name, []).append(not o.hide_render and not o.hide_viewport)
print(json.dumps(shown))
"""


def test_creatures_that_come_and_go_are_hidden_while_they_are_not_there(
    blender_env: dict[str, str], tmp_path: Path
) -> None:
    """`b` despawned after frame 4, `late` spawned after frame 6: their skins are hidden
    (viewport and render) exactly while the take says they are not there."""

    take = come_and_go_take()
    path = tmp_path / "roster.npz"
    take.save(path)
    shown = run(blender_env, SHOWN, str(path))
    visible = take.visible()
    assert sorted(shown) == ["a_skin", "b_skin", "late_skin"]
    for c, name in enumerate(("a", "b", "late")):
        assert shown[f"{name}_skin"] == visible[:, c].tolist(), name


GROUND = """
bpy.ops.import_scene.ecs_tentacles_take(filepath=sys.argv[1])
def shader(material):
    return next(n for n in material.node_tree.nodes if n.type == "BSDF_PRINCIPLED")
print(json.dumps({
    o.name: {
        "parent": o.parent and o.parent.name,
        "vertices": len(o.data.vertices),
        "triangles": len(o.data.polygons),
        "materials": [[m.name, list(shader(m).inputs["Base Color"].default_value)[:3]]
                      for m in o.data.materials],
    }
    for o in bpy.context.scene.objects if o.type == "MESH" and not o.name.endswith("_skin")
}))
"""


def test_the_terrain_comes_in_as_the_usd_import_shows_it(
    blender_env: dict[str, str], tmp_path: Path
) -> None:
    """rocky_shore: the heightfield (`surface`) and the obstacles under `terrain`, each
    with its mesh and a material of the sandbox's colour."""
    path = tmp_path / "shore.npz"
    argv = ["bake", "rocky_shore", "--seconds", "0.2", "--fps", "30", "--quiet"]
    assert main([*argv, "--out", str(path)]) == 0
    found = run(blender_env, GROUND, str(path))
    take = Take.load(path)
    colours = take.ground_colours()
    assert sorted(found) == ["obstacles", "surface"]
    for name, mesh in (("surface", "terrain"), ("obstacles", "obstacles")):
        entry = next(m for m in take.header["ground"]["meshes"] if m["name"] == mesh)
        made = found[name]
        assert made["parent"] == "terrain"
        assert (made["vertices"], made["triangles"]) == (entry["vertices"], entry["triangles"])
        ((material, colour),) = made["materials"]
        assert material == f"{name}_material"
        np.testing.assert_allclose(colour, to_linear(colours[mesh]), atol=1e-6)
