"""Benchmark: a take opened in Blender through the add-on (`ecs-tentacles blender-addon`):
the import's wall time and the Blender process's peak memory, and whether sampled
creatures move and sit where the take has them.

    python tools/bench_blender_addon.py crowd.npz --blender /path/to/python-with-bpy
    python tools/bench_blender_addon.py crowd.npz --sample 32 --json

The add-on is installed into a fresh Blender user folder (`BLENDER_USER_RESOURCES`), then
one Blender process imports the take (`bpy.ops.import_scene.ecs_tentacles_take`) and
reads, for `--sample` creatures spread over the take, their mantles' world positions
(the depsgraph evaluated) at its first, middle and last frames; the mantles are compared
with the take's (`ecs_tentacles.take`), and a creature moves when a bone of it moved
more than 1 cm between the first frame and another. Peak memory is the Blender
process's own (`wait4`). One JSON line with `--json`.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

IMPORT = """
import json, sys, time, bpy
bpy.ops.wm.read_userpref()
bpy.ops.wm.read_homefile(use_empty=True)
start = time.perf_counter()
bpy.ops.import_scene.ecs_tentacles_take(filepath=sys.argv[1])
seconds = time.perf_counter() - start
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
print(json.dumps({"import_s": seconds, "mantles": mantles, "bones": bones,
                  "actions": len(bpy.data.actions), "objects": len(bpy.data.objects)}))
"""


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


def reference(take: Path, creatures: list[int], frames: list[int]) -> tuple[list[str], np.ndarray]:
    """The sampled creatures' names and their mantles' positions (frames, n, 3) in the take."""
    from ecs_tentacles.take import Take

    loaded = Take.load(take)
    entries = [loaded.header["creatures"][c] for c in creatures]
    mantles = [e["mantle"] for e in entries]
    return [e["name"] for e in entries], loaded.pos[np.ix_(frames, mantles)].astype(np.float64)


def bench(take: Path, blender: str, sample: int) -> dict[str, Any]:
    """Install the add-on, import `take` in Blender; the figures (see the module)."""
    from ecs_tentacles.cli import main
    from ecs_tentacles.take import Take

    header = Take.read_header(take)
    count, frames_in = len(header["creatures"]), int(header["frames"])
    creatures = sorted({round(i) for i in np.linspace(0, count - 1, min(sample, count))})
    frames = [0, frames_in // 2, frames_in - 1]
    names, expected = reference(take, creatures, frames)
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
    found = json.loads(out.splitlines()[-1])
    mantles = np.array(found["mantles"])
    bones = np.array(found["bones"])  # (frames, n, J, 3)
    moved = np.linalg.norm(bones[1:] - bones[:1], axis=-1).max(axis=(0, 2))
    return {
        "take": take.name,
        "creatures": count,
        "frames": frames_in,
        "fps": header["fps"],
        "import_s": round(found["import_s"], 2),
        "blender_s": round(wall, 2),
        "blender_peak_gb": round(peak / 1e9, 3),
        "sampled": len(names),
        "moving": int((moved > 0.01).sum()),
        "mantle_error_mm": round(
            1000 * float(np.linalg.norm(mantles - expected, axis=-1).max()), 4
        ),
        "actions": found["actions"],
        "objects": found["objects"],
        "load": [round(x, 2) for x in os.getloadavg()],
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("take", type=Path, help="a take (.npz)")
    parser.add_argument(
        "--blender",
        default=os.environ.get("ECS_TENTACLES_BLENDER_PYTHON", "blender"),
        help="Blender or a Python with bpy (default: $ECS_TENTACLES_BLENDER_PYTHON, blender)",
    )
    parser.add_argument("--sample", type=int, default=32, help="creatures checked (default 32)")
    parser.add_argument("--json", action="store_true", help="one JSON line")
    args = parser.parse_args()
    row = bench(args.take, args.blender, args.sample)
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


if __name__ == "__main__":
    main()
