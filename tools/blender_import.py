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
  `/World/terrain/terrain_materials`) are removed;
* USD shapes: Blender's USD importer binds no material to a Capsule or Cylinder prim
  (the rigid form's bodies), so each such mesh gets its creature's `<c>_material` here.

`--report` prints, as JSON, what the artist finds: the scene's objects by type, objects
made but kept out of the scene, how many armatures move through their active action.

`--render shot.png --frame 60` also renders one still of the import as it stands
(written whole or not at all): Blender's Workbench engine (no GPU needed), solid
shading in the materials' colours and textures, a camera looking down from the
south-west at every creature and the terrain's obstacles, a sun. The camera and the
sun stay in the .blend (`--out`, optional with `--render`).

    python tools/blender_import.py take.glb --render take.png --frame 60

Needs `bpy` (`pip install bpy==5.0.1` in a venv of its own: it pins numpy 1.26) or
Blender itself; uses nothing else outside the standard library.
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import math
import re
import struct
import sys
from collections.abc import Callable
from contextlib import AbstractContextManager
from fractions import Fraction
from pathlib import Path
from types import ModuleType
from typing import Any

USD = (".usd", ".usda", ".usdc")
# a USD Scope of materials, as an empty: `materials` (`materials_1` beside a creature
# called materials), the ground's `terrain_materials` (`terrain_ground_materials` beside
# a creature called terrain); `.001`: older exports
MATERIAL_SCOPE = re.compile(r"(?:terrain(?:_ground)?_)?materials(?:_[0-9]+)?(?:\.[0-9]{3})?")


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


def build_parser() -> argparse.ArgumentParser:
    """The tool's arguments (the docs tests parse the handbook's lines with it)."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("take", type=Path, help="an export: .usd, .usda, .usdc or .glb")
    parser.add_argument("--out", type=Path, help="the .blend to write")
    parser.add_argument(
        "--report",
        action="store_true",
        help="also print what the import made (objects by type, armatures that animate) as JSON",
    )
    parser.add_argument(
        "--render",
        type=Path,
        metavar="PNG",
        help="also render a still (Workbench, material colours) of every creature and the"
        " terrain's obstacles, from a camera set up for it under a sun",
    )
    parser.add_argument(
        "--frame",
        type=int,
        help="the frame --render shows (default: the middle of the take)",
    )
    parser.add_argument(
        "--size",
        type=size,
        default=(960, 540),
        metavar="WxH",
        help="the still's size in pixels (default 960x540)",
    )
    return parser


def main(argv: list[str] | None = None) -> int:
    if argv is None:  # inside Blender the script's own arguments follow `--`
        argv = sys.argv[sys.argv.index("--") + 1 :] if "--" in sys.argv else sys.argv[1:]
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.out is None and args.render is None:
        parser.error("give --out (a .blend), --render (a .png) or both")
    if args.render is not None and args.render.suffix.lower() != ".png":
        parser.error(f"argument --render: must end in .png, got {args.render}")
    if args.frame is not None and args.render is None:
        parser.error("argument --frame: only with --render")
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
    rate = f"{fps:g} fps" if fps else "the file names no frame rate: Blender's default"
    if args.render is not None:
        frame = (scene.frame_start + scene.frame_end) // 2 if args.frame is None else args.frame
        if not scene.frame_start <= frame <= scene.frame_end:
            raise SystemExit(
                f"error: --frame {frame}: the take spans frames"
                f" {scene.frame_start}-{scene.frame_end}"
            )
        shown = render(bpy, args.render, frame, args.size)
        print(f"{args.render}: {args.size[0]}x{args.size[1]}, frame {frame}, {shown}")
    if args.out is not None:
        bpy.ops.wm.save_as_mainfile(filepath=str(args.out.resolve()))
    if args.report:
        print(json.dumps(report(bpy)))
    made = args.out if args.out is not None else args.render
    print(f"{made}: {args.take.name} at {rate}, frames {scene.frame_start}-{scene.frame_end}")
    return 0


def atomic_output(target: Path) -> AbstractContextManager[Path]:
    """`ecs_tentacles.output.atomic.atomic_output` (the project's one output writer), from the
    repository this tool sits in when the Python running it (Blender's) lacks the
    project; the module needs only the standard library."""
    module: ModuleType
    try:
        from ecs_tentacles.output import atomic as module
    except ImportError:
        file = Path(__file__).resolve().parents[1] / "ecs_tentacles" / "output" / "atomic.py"
        spec = importlib.util.spec_from_file_location("ecs_tentacles_atomic", file)
        if spec is None or spec.loader is None:
            raise SystemExit(f"error: --render needs {file} (the project's writer)") from None
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
    writer: Callable[[Path], AbstractContextManager[Path]] = module.atomic_output
    return writer(target)


def size(text: str) -> tuple[int, int]:
    """`960x540` -> (960, 540)."""
    match = re.fullmatch(r"([0-9]+)x([0-9]+)", text)
    if not match or not all(16 <= int(n) <= 8192 for n in match.groups()):
        raise argparse.ArgumentTypeError(f"expected WxH, each 16-8192 pixels, got {text!r}")
    return int(match[1]), int(match[2])


VIEW = (0.45, 1.0, -0.62)  # the camera looks north-north-east, 30 degrees down
SUN = (-0.35, 0.55, -0.76)  # light from the south-west, high: short shadows on the ground
SKY = (0.62, 0.71, 0.80)  # the background, a pale sky (linear)
MARGIN = 1.08  # room round what is framed, as a scale about its centre


def terrain_parts(bpy: object) -> tuple[list[Any], list[Any]]:
    """The scene's meshes: (creatures', the terrain's) - the terrain's are the meshes under
    the ground's root (USD `/World/terrain`, the glb's `terrain` node; `terrain_ground`
    when a creature is called `terrain`)."""
    objects = bpy.context.scene.objects  # type: ignore[attr-defined]
    root = "terrain_ground" if "terrain_ground" in objects else "terrain"
    creatures: list[Any] = []
    terrain: list[Any] = []
    for o in objects:
        if o.type != "MESH":
            continue
        parent = o.parent
        while parent is not None and parent.name != root:
            parent = parent.parent
        (creatures if parent is None else terrain).append(o)
    return creatures, terrain


def render(bpy: object, path: Path, frame: int, pixels: tuple[int, int]) -> str:
    """Render `frame` to `path` (written atomically) with Blender's Workbench engine (no
    GPU needed): material colours and textures in studio light, the sun's shadows. The
    camera looks down at every creature and the terrain's obstacles (the ground fills
    the rest); the camera and the sun stay in the scene (and in the .blend). Returns
    what was framed, in words."""
    from mathutils import Vector  # Blender's own, next to bpy

    scene = bpy.context.scene  # type: ignore[attr-defined]
    data = bpy.data  # type: ignore[attr-defined]
    scene.frame_set(frame)
    creatures, terrain = terrain_parts(bpy)
    framed = creatures + [o for o in terrain if "obstacles" in o.name]
    if not framed:  # nothing but ground: all of it
        framed = terrain
    if not framed:
        raise SystemExit("error: --render: the import holds no mesh to show")
    depsgraph = bpy.context.evaluated_depsgraph_get()  # type: ignore[attr-defined]
    corners = []
    for o in framed:
        evaluated = o.evaluated_get(depsgraph)  # skins as their armature poses them
        corners += [evaluated.matrix_world @ Vector(c) for c in evaluated.bound_box]
    centre = sum(corners, Vector()) / len(corners)
    corners = [centre + (c - centre) * MARGIN for c in corners]

    camera = data.objects.new("camera", data.cameras.new("camera"))
    scene.collection.objects.link(camera)
    camera.data.lens = 40
    camera.data.clip_end = 1000
    camera.rotation_euler = Vector(VIEW).to_track_quat("-Z", "Y").to_euler()
    scene.camera = camera
    scene.render.resolution_x, scene.render.resolution_y = pixels
    scene.render.resolution_percentage = 100
    depsgraph.update()
    flat = [x for c in corners for x in c]
    camera.location, _ = camera.camera_fit_coords(depsgraph, flat)

    sun = data.objects.new("sun", data.lights.new("sun", "SUN"))
    scene.collection.objects.link(sun)
    sun.rotation_euler = Vector(SUN).to_track_quat("-Z", "Y").to_euler()
    sun.data.energy = 3.0

    if scene.world is None:
        scene.world = data.worlds.new("sky")
    scene.world.color = SKY
    scene.render.engine = "BLENDER_WORKBENCH"
    shading = scene.display.shading
    shading.light = "STUDIO"
    shading.color_type = "TEXTURE"  # a glb's skin textures; a material's colour otherwise
    shading.show_shadows = True
    shading.shadow_intensity = 0.45
    shading.show_cavity = True
    shading.cavity_type = "WORLD"
    scene.display.light_direction = tuple(-x for x in Vector(SUN).normalized())
    scene.render.film_transparent = False
    scene.view_settings.view_transform = "Standard"  # colours as written (AgX desaturates)
    scene.render.image_settings.file_format = "PNG"
    scene.render.image_settings.color_mode = "RGB"
    scene.render.image_settings.compression = 100
    scene.render.dither_intensity = 0  # dither noise would double the PNG's size
    bpy.ops.render.render()  # type: ignore[attr-defined]
    with atomic_output(path) as temporary:
        data.images["Render Result"].save_render(filepath=str(temporary), scene=scene)
    obstacles = ", the obstacles" if len(framed) > len(creatures) else ""
    ground = " on the ground" if terrain else ""
    return f"{len(creatures)} creature meshes{obstacles}{ground}"


def bind_shapes(bpy: object) -> None:
    """Give every mesh without a material its creature's `<c>_material` (the creature: the
    ancestor right under `World`); a material nothing uses afterwards is removed."""
    data = bpy.data  # type: ignore[attr-defined]
    for mesh in [o for o in data.objects if o.type == "MESH" and not o.data.materials]:
        root = mesh
        while root.parent is not None and root.parent.name != "World":
            root = root.parent
        material = data.materials.get(f"{root.name}_material")
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
