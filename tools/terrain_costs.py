"""What the largest terrain inputs the schema allows cost: wall time and peak resident
memory of `validate` and `run` (the command and its mesh worker apart), one line per case.

    python tools/terrain_costs.py             # every case (the mesh over budget takes ~60 s)
    python tools/terrain_costs.py --quick     # without the mesh that runs to its budget

Cases (each with the limit that bounds it):
- image: a 1024 x 1024 16-bit noise PNG (sides <= 1024), and a 20000^2 decompression bomb;
- heights: a 1024 x 1024 `heights` array (rows and columns <= 1024);
- mesh: a 100-triangle soup that CoACD cannot finish (60 s / 1024 MB per mesh), 1,000
  obstacles naming one concave OBJ (one decomposition per distinct file), the same
  again with the cache warm.
Files are written in a temporary folder with its own mesh cache. "children" is the
largest process the command started and waited for (the mesh worker; about 68 MB is
a helper a library starts at import).
"""

from __future__ import annotations

import argparse
import json
import os
import struct
import subprocess
import sys
import tempfile
import time
import zlib
from collections.abc import Mapping
from pathlib import Path

import numpy as np

MEASURE = """
import resource, sys, time
from ecs_tentacles.cli import main
start = time.perf_counter()
code = main(sys.argv[1:])
wall = time.perf_counter() - start
me = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
workers = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024
print(f"@@ {code} {wall:.2f} {me:.0f} {workers:.0f}", file=sys.stderr)
"""


def scene(folder: Path, name: str, terrain: Mapping[str, object]) -> Path:
    path = folder / f"{name}.json"
    creature = {"name": "c0", "position": [0, 0]}
    path.write_text(json.dumps({"version": 1, "terrain": terrain, "creatures": [creature]}))
    return path


def bomb(path: Path, side: int) -> None:
    def chunk(kind: bytes, data: bytes) -> bytes:
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body))

    squeeze = zlib.compressobj(1)
    row = bytes(side + 1)
    stream = b"".join(squeeze.compress(row) for _ in range(side)) + squeeze.flush()
    header = struct.pack(">IIBBBBB", side, side, 8, 0, 0, 0, 0)
    path.write_bytes(
        b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", stream) + chunk(b"IEND", b"")
    )


def cases(folder: Path, quick: bool) -> list[tuple[str, Path]]:
    from PIL import Image

    rng = np.random.default_rng(0)
    found = []
    pixels = (rng.random((1024, 1024)) * 65535).astype(np.uint16)
    Image.fromarray(pixels).save(folder / "noise1024.png")
    image = {"heightfield": {"size": [40, 40], "image": "noise1024.png", "height": 0.3}}
    found.append(("image 1024 x 1024 16-bit (sides <= 1024)", scene(folder, "image", image)))
    bomb(folder / "bomb.png", 20_000)
    image = {"heightfield": {"size": [40, 40], "image": "bomb.png"}}
    found.append(("image 20000^2 bomb (refused from its header)", scene(folder, "bomb", image)))
    heights = np.round(rng.random((1024, 1024)) * 0.3, 4).tolist()
    field = {"heightfield": {"size": [40, 40], "heights": heights}}
    found.append(("heights 1024 x 1024 (rows, columns <= 1024)", scene(folder, "heights", field)))
    import trimesh

    top = trimesh.transformations.translation_matrix((0, 0, 1.15))
    legs = [
        trimesh.creation.box((0.3, 1, 1), trimesh.transformations.translation_matrix((x, 0, 0.5)))
        for x in (-0.6, 0.6)
    ]
    trimesh.util.concatenate([*legs, trimesh.creation.box((1.5, 1, 0.3), top)]).export(
        folder / "arch.obj"
    )
    rocks = [
        {
            "shape": "mesh",
            "file": "arch.obj",
            "position": [-60 + 4 * (i % 30), 6 + 4 * (i // 30), 0],
        }
        for i in range(1000)
    ]
    path = scene(folder, "arches", {"obstacles": rocks})
    found.append(("mesh: 1000 obstacles of one concave OBJ, cache cold", path))
    found.append(("mesh: the same, cache warm", path))
    if not quick:
        corners = rng.uniform(-1.0, 1.0, (300, 3))
        text = [f"v {x:.6f} {y:.6f} {z:.6f}" for x, y, z in corners]
        text += [f"f {3 * k + 1} {3 * k + 2} {3 * k + 3}" for k in range(100)]
        (folder / "soup.obj").write_text("\n".join(text) + "\n")
        soup = {"obstacles": [{"shape": "mesh", "file": "soup.obj", "position": [5, 5, 0]}]}
        found.append(
            ("mesh: 100-triangle soup (60 s, 1024 MB per mesh)", scene(folder, "soup", soup))
        )
    return found


def measure(command: list[str], env: dict[str, str]) -> str:
    done = subprocess.run(
        [sys.executable, "-c", MEASURE, *command], capture_output=True, text=True, env=env
    )
    tail = [line for line in done.stderr.splitlines() if line.startswith("@@ ")]
    if not tail:
        return f"failed: {done.stderr.strip()[-200:]}"
    code, wall, me, workers = tail[-1].split()[1:]
    errors = [line for line in done.stderr.splitlines() if line.startswith("error:")]
    said = f"  [{errors[0][:110]}]" if errors else ""
    return f"exit {code}  {wall:>6} s  command {me:>5} MB  children {workers:>5} MB{said}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "--quick", action="store_true", help="skip the mesh that runs to its budget"
    )
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as name:
        folder = Path(name)
        env = {**os.environ, "XDG_CACHE_HOME": str(folder / "cache")}
        for label, path in cases(folder, args.quick):
            print(label)
            for command in ("validate", "run"):
                if "warm" in label and command == "validate":
                    continue
                extra = ["--frames", "10", "--quiet"] if command == "run" else []
                started = time.perf_counter()
                line = measure([command, str(path), *extra], env)
                print(f"  {command:<8} {line}  ({time.perf_counter() - started:.1f} s in all)")


if __name__ == "__main__":
    main()
