"""Benchmark: a crowd's glb, skinned and rigid: `ecs-tentacles export`'s wall time and
peak memory, the file's size against the size counted before any work, and (with
`--blender`) what Blender's glTF importer takes to open it.

    python tools/bench_glb.py --creatures 64 --seconds 5          # bakes a uniform crowd
    python tools/bench_glb.py --take crowd.npz --json
    python tools/bench_glb.py --take crowd.npz --blender /path/to/python-with-bpy

One row per form. Each command runs in a process of its own (peak memory is its own,
from `wait4`). Measured on this 2-core machine (load 2.5-5: others were measuring): the
1,024 uniform crowd, 2 s at 60 fps (a 316 MB take), skinned 570 MB in 46.8 s and
1.34 GB (before streaming: 59.8 s, 3.55 GB), rigid 386 MB in 19.6 s and 1.10 GB (27.3 s,
1.82 GB), the same bytes; counted 4.6 and 5.4 % over. Blender 5.0.1 opened 64 creatures
x 301 frames (51 MB skinned) in 24 s at 1.36 GB, x 901 frames (101 MB) in 37 s at
3.14 GB; the rigid 50 MB in 103 s at 2.12 GB (`export.glb_size.BLENDER_*`).
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

BLENDER_IMPORT = """
import sys, time, bpy
bpy.ops.wm.read_factory_settings(use_empty=True)
start = time.perf_counter()
bpy.ops.import_scene.gltf(filepath=sys.argv[1], disable_bone_shape=True)
print("seconds", time.perf_counter() - start)
"""


def measured(command: list[str]) -> tuple[float, int, str]:
    """(wall seconds, peak resident bytes, stdout) of `command`, run to its end."""
    start = time.perf_counter()
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL)
    assert process.stdout is not None
    out = process.stdout.read().decode()
    _, status, usage = os.wait4(process.pid, 0)
    process.returncode = os.waitstatus_to_exitcode(status)
    if process.returncode:
        raise SystemExit(f"{' '.join(command)}: exit {process.returncode}")
    return time.perf_counter() - start, usage.ru_maxrss * 1024, out


def bench(take: Path, folder: Path, blender: str | None) -> list[dict[str, Any]]:
    """Export `take` skinned and rigid into `folder`; a row for each."""
    from ecs_tentacles.export.glb_size import glb_size, shapes_of_header
    from ecs_tentacles.skin.mesh import Detail
    from ecs_tentacles.take import Take

    shapes = shapes_of_header(Take.read_header(take))
    rows = []
    for form, flags, detail in (("skinned", [], Detail()), ("rigid", ["--rigid"], None)):
        out = folder / f"{form}.glb"
        command = [sys.executable, "-m", "ecs_tentacles", "export", str(take), "--out", str(out)]
        seconds, peak, _ = measured([*command, "--quiet", *flags])
        size = glb_size(shapes, detail)
        written = out.stat().st_size
        row: dict[str, Any] = {
            "form": form,
            "creatures": len(shapes.creatures),
            "frames": shapes.frames,
            "export_s": round(seconds, 1),
            "export_peak_gb": round(peak / 1e9, 2),
            "glb_mb": round(written / 1e6, 1),
            "counted_over_pct": round(100 * (size.total() / written - 1), 1),
            "blender_estimate_gb": round(size.blender_bytes() / 1e9, 2),
        }
        if blender:
            seconds, peak, _ = measured([blender, "-c", BLENDER_IMPORT, str(out)])
            row["blender_s"], row["blender_peak_gb"] = round(seconds, 1), round(peak / 1e9, 2)
        rows.append(row)
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--take", type=Path, help="a take to export (default: bake one)")
    parser.add_argument("--creatures", type=int, default=64, help="a uniform crowd to bake")
    parser.add_argument("--seconds", type=float, default=5.0, help="of the crowd's bake")
    parser.add_argument("--blender", help="a Python with bpy: time Blender's glTF import too")
    parser.add_argument("--json", action="store_true", help="rows as JSON lines")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as name:
        folder = Path(name)
        take = args.take
        if take is None:
            from ecs_tentacles.creator.crowd import crowd_scene

            scene, take = folder / "crowd.json", folder / "crowd.npz"
            scene.write_text(json.dumps(crowd_scene(args.creatures, 3, uniform=True)))
            measured([sys.executable, "-m", "ecs_tentacles", "bake", str(scene), "--seconds",
                      str(args.seconds), "--out", str(take), "--quiet"])  # fmt: skip
        for row in bench(take, folder, args.blender):
            print(json.dumps(row) if args.json else "  ".join(f"{k} {v}" for k, v in row.items()))


if __name__ == "__main__":
    main()
