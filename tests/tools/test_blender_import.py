"""tools/blender_import.py in Blender (bpy 5.0.1): exports open at their own frame rate
and range, with one material and names as written."""

from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path
from typing import Any

import pytest

from ecs_tentacles.cli import main

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


@pytest.mark.parametrize("suffix", [".usdc", ".glb"])
def test_an_export_opens_in_blender_at_its_rate_and_range(tmp_path: Path, suffix: str) -> None:
    take = tmp_path / f"take{suffix}"
    argv = ["bake", "octopus", "--seconds", "1", "--fps", "30", "--out", str(take), "--quiet"]
    assert main(argv) == 0
    blend = tmp_path / "take.blend"
    done = subprocess.run(
        [BLENDER, str(TOOL), str(take), "--out", str(blend)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines()[-1] == f"{blend}: {take.name} at 30 fps, frames 0-30"
    read = subprocess.run(
        [BLENDER, "-c", READ, str(blend)], capture_output=True, text=True, timeout=120
    )
    found = json.loads(read.stdout.splitlines()[-1])
    assert found["fps"] == 30 and found["range"] == [0, 30]  # 31 frames, 1 s at 30 fps
    assert found["actions"] and all(a == [0.0, 30.0] for a in found["actions"])
    assert found["materials"] == ["skin"]  # USD imports it too, not grey


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
    done = subprocess.run(
        [BLENDER, str(TOOL), str(take), "--out", str(blend)],
        capture_output=True,
        text=True,
        timeout=180,
    )
    assert done.returncode == 0, done.stderr
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
