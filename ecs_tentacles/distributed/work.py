"""The work folder of a distributed bake: finished shards, kept until the merge.

`take.npz` bakes into `.take.npz.work/` beside it. Each finished shard is written
there atomically as `<key>.npz` (its take's arrays, its contact spheres and its
creatures), keyed by a hash of everything its result depends on: the scene, the
shard's creatures, the bake settings and this package's version. A changed scene or
setting therefore never reuses old work. `--resume` loads the shards found there;
the folder is removed once the merged output is written.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import re
import shutil
import zipfile
from pathlib import Path

import numpy as np

from ecs_tentacles.distributed.task import ShardResult
from ecs_tentacles.export.bake import BakePlan
from ecs_tentacles.output.atomic import atomic_file
from ecs_tentacles.take import Take, write_npz

_KEY = re.compile(r"^[0-9a-f]{24}\.npz$")


def work_folder(out: Path) -> Path:
    """`.<name>.work` beside the output `out`."""
    return out.with_name(f".{out.name}.work")


def shard_key(plan: BakePlan, members: list[int], allow_systems: bool) -> str:
    """24 hex digits naming one shard's result under these exact settings."""
    from ecs_tentacles import __version__

    settings = {
        "scene": plan.scene_sha256,
        "members": members,
        "seconds": plan.seconds,
        "fps": plan.fps,
        "sim_fps": plan.sim_fps,
        "seed": plan.seed,
        "allow_systems": allow_systems,
        "version": __version__,
    }
    text = json.dumps(settings, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:24]


def save_shard(folder: Path, key: str, result: ShardResult) -> None:
    """Write one finished shard atomically."""
    folder.mkdir(exist_ok=True)
    arrays = result.take.arrays()
    arrays["spheres"] = result.spheres
    arrays["members"] = np.asarray(result.members, dtype=np.int64)
    with atomic_file(folder / f"{key}.npz") as handle:
        write_npz(handle, arrays)


def load_shard(folder: Path, key: str) -> ShardResult | None:
    """The shard saved under `key`, or None when absent or unreadable (then re-baked)."""
    path = folder / f"{key}.npz"
    if not path.is_file():
        return None
    try:
        with np.load(path, allow_pickle=False) as data:
            header = json.loads(bytes(data["header"]).decode())
            own = ("header", "spheres", "members")
            arrays = {k: data[k] for k in data.files if k not in own}
            take = Take.from_arrays(header, arrays)
            result = ShardResult(data["members"].tolist(), take, data["spheres"])
    except (OSError, ValueError, KeyError, zipfile.BadZipFile):
        return None
    return None if take.problem() else result


def remove_work(folder: Path) -> None:
    """Delete the work folder if it holds only shard results (and their partials)."""
    if not folder.is_dir():
        return
    names = [p.name for p in folder.iterdir()]
    if all(_KEY.match(n) or ".partial" in n for n in names):
        shutil.rmtree(folder, ignore_errors=True)
    else:
        for name in filter(_KEY.match, names):
            with contextlib.suppress(OSError):
                (folder / name).unlink()
