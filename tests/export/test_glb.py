"""The GLB container: the writers stream the binary chunk through a spool, so a file is
written with memory far below its size, bit for bit the file built in memory; a stop
or a file past 4 GiB leaves nothing in the folder."""

from __future__ import annotations

import json
import tracemalloc
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import ecs_tentacles.export.glb as glb
from ecs_tentacles.export.glb import GlbTooLarge, glb_bytes
from ecs_tentacles.export.gltf import build_gltf, write_glb
from ecs_tentacles.export.skinned_gltf import build_skinned_gltf, write_skinned_glb
from ecs_tentacles.take import Take
from tests.terminal import export_stopped_leaves_only_the_take

ROOT = Path(__file__).resolve().parents[2]


def _longer(take: Take, frames: int, creatures: int = 1) -> Take:
    """`take` played back and forth to `frames` frames, its creature repeated
    `creatures` times side by side (a real take: `Take.problem` finds nothing)."""
    order = np.arange(frames) % (2 * take.frames - 2)
    order = np.where(order < take.frames, order, 2 * take.frames - 2 - order)
    header = json.loads(json.dumps(take.header))
    bodies, per = header["bodies"], len(header["bodies"])
    entry = header["creatures"][0]
    header["creatures"], header["bodies"], header["suckers"] = [], [], []
    for c in range(creatures):
        name, first = f"c{c}", c * per

        def renamed(item: dict[str, Any], name: str = name, **more: Any) -> dict[str, Any]:
            return {**item, **more, "name": name + item["name"][len("octo") :]}

        chains = [[first + i for i in chain] for chain in entry["tentacles"]]
        header["creatures"].append(renamed(entry, mantle=first + entry["mantle"], tentacles=chains))
        header["bodies"] += [renamed(body, creature=c) for body in bodies]
        header["suckers"] += [renamed(s, body=first + s["body"]) for s in take.header["suckers"]]
    header["frames"], header["goals"], header["guides"] = frames, [], None
    header.pop("replay", None)  # nobody replays here
    apart = np.repeat(np.arange(creatures) * 2.0, per)[None, :, None] * [1.0, 0.0, 0.0]
    arrays = {
        "pos": (np.tile(take.pos[order], (1, creatures, 1)) + apart).astype(np.float32),
        "quat": np.tile(take.quat[order], (1, creatures, 1)),
        "sucker_attached": np.tile(take.sucker_attached[order], (1, creatures)),
        "sucker_anchor": np.tile(take.sucker_anchor[order], (1, creatures, 1)),
        "goal_pos": np.zeros((0, 3), np.float32),
        "goal_active": np.zeros((frames, 0), bool),
    }
    longer = Take.from_arrays(header, arrays)
    assert longer.problem() is None
    return longer


def _peak(write: Callable[[], object]) -> int:
    """The most memory (bytes, Python's and numpy's) held at once while `write` runs."""
    tracemalloc.start()
    try:
        write()
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


def test_a_rigid_glb_is_written_with_memory_a_fraction_of_its_size(
    guided_take: Take, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """416 bodies x 2,000 frames (a 24 MB file): a block of bodies turned y-up at a time
    (4 here), the bytes spooled; building it in memory held the file three times over."""
    take = _longer(guided_take, 2_000, creatures=32)
    monkeypatch.setattr("ecs_tentacles.export.gltf.BLOCK_BYTES", 1024**2)
    monkeypatch.setattr("ecs_tentacles.take.entries.CHECK_BYTES", 1024**2)  # the take's checks
    path = tmp_path / "long.glb"
    peak = _peak(lambda: write_glb(take, path))
    size = path.stat().st_size
    assert size > 23_000_000 and peak < 0.3 * size, (peak, size)
    assert path.read_bytes() == glb_bytes(*build_gltf(take))  # the same bytes, streamed


def test_a_skinned_glb_is_written_one_creature_at_a_time(guided_take: Take, tmp_path: Path) -> None:
    """40 more creatures add less memory than they add to the file (their JSON): one
    creature's rig (animation, keys, mesh) is held at a time. Holding every rig to the
    end, they added 5 times what they add to the file."""
    peaks, sizes = [], []
    for creatures in (8, 48):
        take = _longer(guided_take, 300, creatures=creatures)
        path = tmp_path / f"crowd{creatures}.glb"
        peaks.append(_peak(lambda take=take, path=path: write_skinned_glb(take, path)))
        sizes.append(path.stat().st_size)
    assert sizes[1] > 5.5 * sizes[0] and peaks[1] - peaks[0] < sizes[1] - sizes[0], (peaks, sizes)
    document, binary, _ = build_skinned_gltf(take)
    assert path.read_bytes() == glb_bytes(document, binary)  # the same bytes, streamed
    assert len(document["skins"]) == 48


def test_a_stop_while_writing_leaves_nothing(guided_take: Take, tmp_path: Path) -> None:
    """Ctrl-C once the first bodies (creature) are in the spool: no file, no partial
    file, no spool left in the folder."""
    take = _longer(guided_take, 200, creatures=4)

    def stop(n: int) -> None:
        raise KeyboardInterrupt

    for write in (write_glb, write_skinned_glb):
        with pytest.raises(KeyboardInterrupt):
            write(take, tmp_path / "crowd.glb", progress=stop)  # type: ignore[operator]
        assert list(tmp_path.iterdir()) == []


def test_the_writer_refuses_a_file_past_what_a_glb_holds(
    guided_take: Take, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The last guard, after the count from shapes: the file as made, over the limit."""
    size = len(glb_bytes(*build_gltf(guided_take)))
    monkeypatch.setattr(glb, "GLB_MAX_BYTES", size - 1)
    with pytest.raises(GlbTooLarge, match=rf"take\.glb: the glb would be {size:,} bytes; a glb"):
        write_glb(guided_take, tmp_path / "take.glb")
    assert list(tmp_path.iterdir()) == []
    monkeypatch.setattr(glb, "GLB_MAX_BYTES", size)
    write_glb(guided_take, tmp_path / "take.glb")
    assert (tmp_path / "take.glb").stat().st_size == size


@pytest.mark.usefixtures("ctrl_c_reaches_children")
def test_ctrl_c_while_a_glb_is_written_leaves_only_the_take(
    guided_take: Take, tmp_path: Path
) -> None:
    """A real export on a terminal, stopped once its bar shows creatures written."""
    take = tmp_path / "crowd.npz"
    _longer(guided_take, 1000, creatures=48).save(take)
    export_stopped_leaves_only_the_take(take, "crowd.glb", r"write crowd\.glb: .*\| ?([1-9]\d*)/48")
