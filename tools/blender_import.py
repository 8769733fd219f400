"""Open an ecs_tentacles export in Blender at its own frame rate and frame range.

    python tools/blender_import.py take.usdc --out take.blend     # a Python with `bpy`
    blender --background --python tools/blender_import.py -- take.glb --out take.blend

Blender's importers keep the scene at 24 fps: a 60 fps take then plays 2.5 times slow,
and a glb's frame range stays at 1-250 whatever the animation spans. This script
imports USD (.usd, .usda, .usdc) or glTF (.glb) the way the files are meant, then saves
a .blend:

* glb: the rate comes from the file's `asset.extras.fps` and is set *before* the import
  (the importer turns animation seconds into frames at the scene's rate);
* USD: the importer places keys by time code (one per take frame); the rate is the
  `ecs:fps` the exporter writes on each creature's root prim (an imported custom
  property), set after the import;
* either: the frame range is that of the imported actions;
* a tidy outliner: the glTF importer's bone shapes (an `Icosphere` per armature, in a
  hidden collection linked to the scene) are not made (bones draw as Blender's own), and
  the empties the USD importer makes of the material scopes (`/World/materials`,
  `/World/terrain/materials`: `materials`, `materials.001`) are removed;
* USD shapes: Blender's USD importer binds no material to a Capsule or Cylinder prim
  (the rigid form's bodies), so each such mesh gets its creature's `<c>_skin` here.

`--report` prints, as JSON, what the artist finds: the scene's objects by type, objects
made but kept out of the scene, how many armatures move through their active action.

Needs `bpy` (`pip install bpy==5.0.1` in a venv of its own: it pins numpy 1.26) or
Blender itself; uses nothing else outside the standard library.
"""

from __future__ import annotations

import argparse
import json
import math
import re
import struct
import sys
from fractions import Fraction
from pathlib import Path

USD = (".usd", ".usda", ".usdc")
MATERIAL_SCOPE = re.compile(r"materials(\.[0-9]{3})?")  # a USD Scope of materials, as an empty


def glb_fps(path: Path) -> float | None:
    """`asset.extras.fps` of a binary glTF (None when it has none)."""
    with path.open("rb") as handle:
        magic, _, _ = struct.unpack("<4sII", handle.read(12))
        length, kind = struct.unpack("<I4s", handle.read(8))
        if magic != b"glTF" or kind != b"JSON":
            raise SystemExit(f"error: {path}: not a binary glTF file")
        document = json.loads(handle.read(length))
    fps = document.get("asset", {}).get("extras", {}).get("fps")
    return float(fps) if isinstance(fps, (int, float)) and fps > 0 else None


def set_rate(scene: object, fps: float) -> None:
    """`scene.render.fps` / `fps_base` for `fps` (integer rates exactly, others closely)."""
    ratio = Fraction(fps).limit_denominator(1001)
    scene.render.fps = ratio.numerator  # type: ignore[attr-defined]
    scene.render.fps_base = ratio.denominator  # type: ignore[attr-defined]


def main(argv: list[str] | None = None) -> int:
    if argv is None:  # inside Blender the script's own arguments follow `--`
        argv = sys.argv[sys.argv.index("--") + 1 :] if "--" in sys.argv else sys.argv[1:]
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("take", type=Path, help="an export: .usd, .usda, .usdc or .glb")
    parser.add_argument("--out", type=Path, required=True, help="the .blend to write")
    parser.add_argument(
        "--report",
        action="store_true",
        help="also print what the import made (objects by type, armatures that animate) as JSON",
    )
    args = parser.parse_args(argv)
    suffix = args.take.suffix.lower()
    if suffix not in (*USD, ".glb"):
        parser.error(f"argument TAKE: must end in .usd, .usda, .usdc or .glb, got {args.take}")
    if not args.take.is_file():
        parser.error(f"argument TAKE: no such file {args.take}")
    import bpy

    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    fps = None
    if suffix == ".glb":
        fps = glb_fps(args.take)
        if fps:
            set_rate(scene, fps)
        bpy.ops.import_scene.gltf(filepath=str(args.take.resolve()), disable_bone_shape=True)
    else:
        bpy.ops.wm.usd_import(
            filepath=str(args.take.resolve()), set_frame_range=True, import_all_materials=True
        )
        bind_shapes(bpy)
        rates = [float(o["ecs:fps"]) for o in bpy.data.objects if "ecs:fps" in o.keys()]
        fps = max(rates) if rates else None
        if fps:
            set_rate(scene, fps)
        for scope in [o for o in bpy.data.objects if MATERIAL_SCOPE.fullmatch(o.name)]:
            if scope.type == "EMPTY" and not scope.children:
                bpy.data.objects.remove(scope)
    ranges = [action.frame_range for action in bpy.data.actions]
    if ranges:
        scene.frame_start = math.floor(min(r[0] for r in ranges))
        scene.frame_end = math.ceil(max(r[1] for r in ranges))
    bpy.ops.wm.save_as_mainfile(filepath=str(args.out.resolve()))
    rate = f"{fps:g} fps" if fps else "the file names no frame rate: Blender's default"
    if args.report:
        print(json.dumps(report(bpy)))
    print(f"{args.out}: {args.take.name} at {rate}, frames {scene.frame_start}-{scene.frame_end}")
    return 0


def bind_shapes(bpy: object) -> None:
    """Give every mesh without a material its creature's `<c>_skin` (the creature: the
    ancestor right under `World`); a material nothing uses afterwards is removed."""
    data = bpy.data  # type: ignore[attr-defined]
    for mesh in [o for o in data.objects if o.type == "MESH" and not o.data.materials]:
        root = mesh
        while root.parent is not None and root.parent.name != "World":
            root = root.parent
        material = data.materials.get(f"{root.name}_skin")
        if material is not None:
            mesh.data.materials.append(material)
    for material in list(data.materials):
        if material.users == 0:
            data.materials.remove(material)


def report(bpy: object) -> dict[str, object]:
    """What an artist finds after the import: the scene's objects by type, objects made
    but kept out of the scene, and the armatures whose bones move between the first frame
    and the middle one (each through its active action)."""
    data = bpy.data  # type: ignore[attr-defined]
    scene = bpy.context.scene  # type: ignore[attr-defined]
    shown = list(scene.objects)
    armatures = [o for o in shown if o.type == "ARMATURE"]

    def poses() -> list[list[float]]:
        return [[x for b in o.pose.bones for row in b.matrix for x in row] for o in armatures]

    scene.frame_set(scene.frame_start)
    first = poses()
    scene.frame_set((scene.frame_start + scene.frame_end) // 2)
    later = poses()
    scene.frame_set(scene.frame_start)
    moving = [
        o.name
        for o, a, b in zip(armatures, first, later, strict=True)
        if o.animation_data
        and o.animation_data.action
        and max((abs(x - y) for x, y in zip(a, b, strict=True)), default=0.0) > 1e-4
    ]
    by_type: dict[str, int] = {}
    for o in shown:
        by_type[o.type] = by_type.get(o.type, 0) + 1
    return {
        "objects": len(shown),
        "by_type": dict(sorted(by_type.items())),
        "outside_scene": sorted(o.name for o in data.objects if o not in shown),
        "armatures": len(armatures),
        "animating": len(moving),
        "materials": len(data.materials),
        "empties": sorted(o.name for o in shown if o.type == "EMPTY"),
    }


if __name__ == "__main__":
    raise SystemExit(main())
