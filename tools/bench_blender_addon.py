"""Benchmark: a take opened in Blender through the add-on (`ecs-tentacles blender-addon`):
the import's wall time and the Blender process's peak memory, and whether sampled
creatures move and sit where the take has them.

    python tools/bench_blender_addon.py crowd.npz --blender /path/to/python-with-bpy
    python tools/bench_blender_addon.py crowd.npz --sample 32 --json
    python tools/bench_blender_addon.py shot.npz --usd     # beside today's USD import

The add-on is installed into a fresh Blender user folder (`BLENDER_USER_RESOURCES`), then
one Blender process imports the take (`bpy.ops.import_scene.ecs_tentacles_take`) and
reads, for `--sample` creatures spread over the take, their mantles' world positions
(the depsgraph evaluated) at its first, middle and last frames; the mantles are compared
with the take's (`ecs_tentacles.take`), and a creature moves when a bone of it moved
more than 1 cm between the first frame and another. Peak memory is the Blender
process's own (`wait4`). With `--usd` the take also goes today's way (`ecs-tentacles
export` to .usdc, `tools/blender_import.py`): its figures, and how far the same creatures'
joints and material colours there are from the add-on's. One JSON line with `--json`.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

READ = """
names, frames = json.loads(sys.argv[2]), json.loads(sys.argv[3])
scene = bpy.context.scene
mantles, bones = [], []
for frame in frames:
    scene.frame_set(frame)
    depsgraph = bpy.context.evaluated_depsgraph_get()
    here, heads = [], []
    for name in names:
        posed = bpy.data.objects[f"{name}_skeleton"].evaluated_get(depsgraph)
        world = posed.matrix_world
        here.append(list(world @ posed.pose.bones["mantle"].head))
        heads.append([list(world @ b.head) for b in posed.pose.bones])
    mantles.append(here)
    bones.append(heads)
def colour(name):
    nodes = bpy.data.materials[f"{name}_material"].node_tree.nodes
    shader = next(n for n in nodes if n.type == "BSDF_PRINCIPLED")
    return list(shader.inputs["Base Color"].default_value)[:3]
print(json.dumps({"import_s": seconds, "mantles": mantles, "bones": bones,
                  "colours": [colour(n) for n in names],
                  "skeletons": sorted(o.name for o in bpy.data.objects if o.type == "ARMATURE"),
                  "actions": len(bpy.data.actions), "objects": len(bpy.data.objects)}))
"""
IMPORT = (
    """
import json, sys, time, bpy
bpy.ops.wm.read_userpref()
bpy.ops.wm.read_homefile(use_empty=True)
start = time.perf_counter()
bpy.ops.import_scene.ecs_tentacles_take(filepath=sys.argv[1])
seconds = time.perf_counter() - start
"""
    + READ
)
OPEN = (
    """
import json, sys, bpy
bpy.ops.wm.open_mainfile(filepath=sys.argv[1])
seconds = 0.0
"""
    + READ
)
TOOL = Path(__file__).resolve().parent / "blender_import.py"


def measured(command: list[str], env: dict[str, str]) -> tuple[float, int, str]:
    """(wall seconds, peak resident bytes, stdout) of `command`, run to its end."""
    start = time.perf_counter()
    with tempfile.TemporaryFile() as errors:
        process = subprocess.Popen(command, env=env, stdout=subprocess.PIPE, stderr=errors)
        assert process.stdout is not None
        out = process.stdout.read().decode()
        _, status, usage = os.wait4(process.pid, 0)
        process.returncode = os.waitstatus_to_exitcode(status)
        if process.returncode:
            errors.seek(0)
            said = errors.read().decode(errors="replace")[-2000:]
            raise SystemExit(f"{command[0]}: exit {process.returncode}: {said}")
    return time.perf_counter() - start, usage.ru_maxrss * 1024, out


def sample(take: Path, count: int) -> tuple[list[int], list[int]]:
    """`count` creatures spread over the take (indices) and its first, middle and last
    frames."""
    from ecs_tentacles.take import Take

    header = Take.read_header(take)
    creatures = len(header["creatures"])
    chosen = sorted({round(i) for i in np.linspace(0, creatures - 1, min(count, creatures))})
    frames = int(header["frames"])
    return chosen, [0, frames // 2, frames - 1]


def mantles_in(
    take: Path, creatures: list[int], frames: list[int]
) -> tuple[dict[str, Any], np.ndarray]:
    """The take's header and the mantles of `creatures` at `frames` (frames, n, 3), read
    a chunk at a time (replayed creatures' poses filled in: `take.stream`)."""
    from ecs_tentacles.take.stream import open_take

    with open_take(take) as source:
        mantles = [source.header["creatures"][c]["mantle"] for c in creatures]
        found = {}
        for first, chunk in source.chunks():
            for f in frames:
                if first <= f < first + chunk.frames:
                    found[f] = chunk.pos[f - first, mantles].astype(np.float64)
        return source.header, np.stack([found[f] for f in frames])


def addon(take: Path, blender: str, names: list[str], frames: list[int]) -> dict[str, Any]:
    """Install the add-on into a fresh user folder and import `take` with it: what READ
    found, and the Blender process's wall time and peak memory."""
    from ecs_tentacles.cli import main

    with tempfile.TemporaryDirectory(prefix="bench-blender-addon-") as folder:
        env = {**os.environ, "BLENDER_USER_RESOURCES": folder}
        os.environ["BLENDER_USER_RESOURCES"] = folder
        try:
            if main(["blender-addon", "--install", "--blender", blender]) != 0:
                raise SystemExit("the add-on did not install")
        finally:
            del os.environ["BLENDER_USER_RESOURCES"]
        command = [blender, "-c", IMPORT, str(take), json.dumps(names), json.dumps(frames)]
        wall, peak, out = measured(command, env)
    found: dict[str, Any] = json.loads(out.splitlines()[-1])
    return {**found, "blender_s": wall, "peak": peak}


def through_usd(take: Path, blender: str, names: list[str], frames: list[int]) -> dict[str, Any]:
    """The take exported to USD and opened by `tools/blender_import.py` (today's path):
    what READ found there, the export's and the import's wall time and peak memory."""
    with tempfile.TemporaryDirectory(prefix="bench-blender-usd-") as folder:
        usd, blend = Path(folder) / f"{take.stem}.usdc", Path(folder) / f"{take.stem}.blend"
        export = [sys.executable, "-m", "ecs_tentacles", "export", str(take), "--out", str(usd),
                  "--quiet"]  # fmt: skip
        export_s, export_peak, _ = measured(export, dict(os.environ))
        opened = [blender, str(TOOL), str(usd), "--out", str(blend)]
        import_s, import_peak, _ = measured(opened, dict(os.environ))
        command = [blender, "-c", OPEN, str(blend), json.dumps(names), json.dumps(frames)]
        _, _, out = measured(command, dict(os.environ))
    found: dict[str, Any] = json.loads(out.splitlines()[-1])
    return {**found, "export_s": export_s, "export_peak": export_peak, "import_s": import_s,
            "import_peak": import_peak}  # fmt: skip


def by_creature(bones: list[list[list[list[float]]]]) -> list[np.ndarray]:
    """READ's bone heads (frames, creatures, bones, 3; bones per creature vary with its
    body plan) as one (frames, bones, 3) array per creature."""
    return [np.array([frame[c] for frame in bones]) for c in range(len(bones[0]))]


def bench(take: Path, blender: str, count: int, usd: bool) -> dict[str, Any]:
    """The add-on's figures for `take` (see the module); with `usd`, today's USD path's
    beside them and how far the two imports differ."""
    creatures, frames = sample(take, count)
    header, expected = mantles_in(take, creatures, frames)
    names = [header["creatures"][c]["name"] for c in creatures]
    found = addon(take, blender, names, frames)
    mantles = np.array(found["mantles"])
    bones = by_creature(found["bones"])  # per creature (frames, J, 3)
    moved = np.array([np.linalg.norm(b[1:] - b[:1], axis=-1).max() for b in bones])
    row: dict[str, Any] = {
        "take": take.name,
        "creatures": len(header["creatures"]),
        "frames": header["frames"],
        "fps": header["fps"],
        "import_s": round(found["import_s"], 2),
        "blender_s": round(found["blender_s"], 2),
        "blender_peak_gb": round(found["peak"] / 1e9, 3),
        "sampled": len(names),
        "moving": int((moved > 0.01).sum()),
        "mantle_error_mm": float(f"{1000 * np.linalg.norm(mantles - expected, axis=-1).max():.3g}"),
        "actions": found["actions"],
        "objects": found["objects"],
    }
    if usd:
        other = through_usd(take, blender, names, frames)
        there = by_creature(other["bones"])
        apart = max(np.linalg.norm(a - b, axis=-1).max() for a, b in zip(there, bones, strict=True))
        row["usd"] = {
            "export_s": round(other["export_s"], 2),
            "export_peak_gb": round(other["export_peak"] / 1e9, 3),
            "import_s": round(other["import_s"], 2),
            "import_peak_gb": round(other["import_peak"] / 1e9, 3),
            "same_creatures": other["skeletons"] == found["skeletons"],
            "joints_apart_mm": float(f"{1000 * apart:.3g}"),
            "colours_apart": float(
                f"{np.abs(np.subtract(other['colours'], found['colours'])).max():.3g}"
            ),
        }
    row["load"] = [round(x, 2) for x in os.getloadavg()]
    return row


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("take", type=Path, help="a take (.npz)")
    parser.add_argument(
        "--blender",
        default=os.environ.get("ECS_TENTACLES_BLENDER_PYTHON", "blender"),
        help="Blender or a Python with bpy (default: $ECS_TENTACLES_BLENDER_PYTHON, blender)",
    )
    parser.add_argument("--sample", type=int, default=32, help="creatures checked (default 32)")
    parser.add_argument(
        "--usd",
        action="store_true",
        help="also export the take to USD and open it with tools/blender_import.py: its"
        " figures, and how far its creatures' joints and colours are from the add-on's",
    )
    parser.add_argument("--json", action="store_true", help="one JSON line")
    args = parser.parse_args()
    row = bench(args.take, args.blender, args.sample, args.usd)
    if args.json:
        print(json.dumps(row))
        return
    print(
        f"{row['take']}: {row['creatures']} creatures x {row['frames']} frames at"
        f" {row['fps']:g} fps: import {row['import_s']} s (Blender {row['blender_s']} s in all,"
        f" peak {row['blender_peak_gb']} GB); {row['moving']} of {row['sampled']} sampled"
        f" creatures move, mantles within {row['mantle_error_mm']} mm of the take;"
        f" load {row['load']}"
    )
    if "usd" in row:
        usd = row["usd"]
        print(
            f"  through USD: export {usd['export_s']} s ({usd['export_peak_gb']} GB), Blender's"
            f" import {usd['import_s']} s ({usd['import_peak_gb']} GB); the same creatures:"
            f" {usd['same_creatures']}, joints {usd['joints_apart_mm']} mm and colours"
            f" {usd['colours_apart']} apart"
        )


if __name__ == "__main__":
    main()
