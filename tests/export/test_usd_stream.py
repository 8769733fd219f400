"""USD written as the take streams: chunk by chunk, saved as it grows, with memory that
does not grow with the take; constant channels written once, the rest state shared by
a body plan's creatures; a stop leaves nothing behind."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import ecs_tentacles.export.usd_layer as usd_layer
from ecs_tentacles.export.skinned_usd import write_skinned_usd
from ecs_tentacles.export.take_chunks import TakeChunks
from ecs_tentacles.export.usd import write_usd
from ecs_tentacles.export.usd_validation import usd_problems
from ecs_tentacles.skin.keys import angle_between
from ecs_tentacles.skin.rig import Keys, Skin
from ecs_tentacles.skin.skeleton import creature_animation, creature_skeleton
from ecs_tentacles.take import Take
from tests.export.test_glb import _longer
from tests.terminal import export_stopped_leaves_only_the_take

ROOT = Path(__file__).resolve().parents[2]

pxr = pytest.importorskip("pxr", reason="USD export needs usd-core (the usd / dev extras)")
from pxr import Sdf, Usd, UsdSkel  # noqa: E402


def _samples(path: Path) -> dict[str, list[Any]]:
    """Every attribute's time samples in the file, by attribute path."""
    layer = Sdf.Layer.FindOrOpen(str(path))
    out: dict[str, list[Any]] = {}

    def visit(spec_path: Any) -> None:
        if spec_path.IsPropertyPath() and layer.GetNumTimeSamplesForPath(spec_path):
            times = layer.ListTimeSamplesForPath(spec_path)
            out[str(spec_path)] = [(t, layer.QueryTimeSample(spec_path, t)) for t in times]

    layer.Traverse("/", visit)
    return out


@pytest.mark.parametrize("skinned", [True, False])
def test_chunk_by_chunk_writes_the_samples_of_the_whole_take(
    guided_take: Take, tmp_path: Path, skinned: bool, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Chunks of 2 frames, the file saved after each (it appends), hold the samples a
    single chunk gives, fur guides and suckers included."""
    take = guided_take
    write: Any = write_skinned_usd if skinned else write_usd
    whole, pieces = tmp_path / "whole.usdc", tmp_path / "pieces.usdc"
    extra: dict[str, Any] = {"locators": True}
    write(TakeChunks(take), whole, **extra)
    monkeypatch.setattr(usd_layer, "FLUSH_BYTES", 1)
    monkeypatch.setattr(usd_layer, "REWRITE_SHARE", 0)  # a save after every chunk
    write(TakeChunks(take, 2), pieces, **extra)
    expected, got = _samples(whole), _samples(pieces)
    assert sorted(got) == sorted(expected) and len(got) > 10
    for name, samples in expected.items():
        assert got[name] == samples, name
    assert usd_problems(pieces) == []


def test_constant_channels_are_written_once_and_the_rest_state_shared(
    guided_take: Take, tmp_path: Path
) -> None:
    """Per frame only rotations and the root's position: a joint's translation in its
    parent does not change, so translations and scales are one value each; two creatures
    of one body plan hold the same skeleton and mesh, which a .usdc stores once."""
    paths = {}
    rng = np.random.default_rng(1)
    for creatures in (2, 6):
        take = _longer(guided_take, 40, creatures=creatures)
        take.quat[:] += rng.normal(0.0, 1e-3, take.quat.shape).astype(np.float32)  # all unlike
        take.quat[:] /= np.linalg.norm(take.quat, axis=-1, keepdims=True)
        paths[creatures] = tmp_path / f"c{creatures}.usdc"
        write_skinned_usd(take, paths[creatures])
    stage = Usd.Stage.Open(str(paths[6]))
    for name in ("c0", "c5"):
        path = f"/World/{name}/{name}_skeleton/{name}_animation"
        anim = UsdSkel.Animation(stage.GetPrimAtPath(path))
        assert anim.GetTranslationsAttr().GetNumTimeSamples() == 0
        assert anim.GetScalesAttr().GetNumTimeSamples() == 0
        assert anim.GetRotationsAttr().GetNumTimeSamples() == 40
        translate = stage.GetPrimAtPath(f"/World/{name}").GetAttribute("xformOp:translate")
        assert translate.GetNumTimeSamples() == 40
    skeleton = creature_skeleton(take, 0)
    np.testing.assert_allclose(
        np.array(anim.GetTranslationsAttr().Get())[1:], skeleton.rest_translation[1:], atol=1e-7
    )
    skins = [stage.GetPrimAtPath(f"/World/{n}/{n}_skin") for n in ("c0", "c5")]
    names = ["points", "normals", "faceVertexIndices", "primvars:st", "primvars:skel:jointIndices"]
    mesh_bytes = 0
    for name in names:  # bound at the origin: the same arrays
        first, other = (skin.GetAttribute(name).Get() for skin in skins)
        assert first == other
        mesh_bytes += np.asarray(first).nbytes
    per_creature = (paths[6].stat().st_size - paths[2].stat().st_size) / 4
    samples = 40 * (16 * len(skeleton.names) + 24)  # its rotations and root positions
    assert per_creature - samples < 0.05 * mesh_bytes, (per_creature, samples, mesh_bytes)


def test_reduced_keys_hold_their_tolerance_across_chunks(octopus_take: Take) -> None:
    """Each chunk is reduced on its own, its ends kept: between keys USD's interpolation
    stays within the tolerance at every frame, the seams included."""
    take = octopus_take
    layer = usd_layer.StreamedLayer(None)
    from ecs_tentacles.export.skinned_usd import _fill

    report = _fill(layer, TakeChunks(take, 16), Skin(keys=Keys("reduced", 0.5)), False, None)
    attr = layer.stage.GetAttributeAtPath(
        "/World/octopus/octopus_skeleton/octopus_animation.rotations"
    )
    expected = creature_animation(creature_skeleton(take, 0), take).rotation
    for frame in range(take.frames):
        got = np.array([[q.GetReal(), *q.GetImaginary()] for q in attr.Get(frame)])
        assert angle_between(got, expected[frame]).max() <= 0.5 + 1e-3
    assert len(attr.GetTimeSamples()) < take.frames and report.after < report.before // 2


GROWTH = """
import sys
from pathlib import Path
import numpy as np
import ecs_tentacles.export.usd_layer as usd_layer
from ecs_tentacles.export.skinned_usd import write_skinned_usd
from ecs_tentacles.export.take_chunks import TakeChunks
from ecs_tentacles.take import Take

def status(key):
    line = next(l for l in Path("/proc/self/status").read_text().splitlines() if l.startswith(key))
    return int(line.split()[1]) / 1024

source, frames, flush, out = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
short = Take.load(source)
write_skinned_usd(short, out)  # USD's plugins loaded, its caches warm
order = np.arange(frames) % short.frames
quat = short.quat[order] + np.random.default_rng(0).normal(0, 1e-3, (frames, *short.quat.shape[1:]))
quat = (quat / np.linalg.norm(quat, axis=-1, keepdims=True)).astype(np.float32)  # all unlike
take = Take({**short.header, "frames": frames}, short.pos[order], quat,
            short.sucker_attached[order], short.sucker_anchor[order],
            {**short.tracks, "goal_active": short.tracks["goal_active"][order]})
usd_layer.FLUSH_BYTES = flush
Path("/proc/self/clear_refs").write_text("5")  # the peak starts again from here
before = status("VmRSS")
write_skinned_usd(TakeChunks(take, 100), out)
print(status("VmHWM") - before, Path(out).stat().st_size / 1024**2)
"""


@pytest.mark.skipif(not os.access("/proc/self/clear_refs", os.W_OK), reason="Linux's peak reset")
def test_memory_does_not_grow_with_the_take(guided_take: Take, tmp_path: Path) -> None:
    """64 creatures of 13 joints, 1,000 then 3,000 frames (about 30 MB more in the file),
    saved as it grows: the peak grows by USD's index of the samples (about 70 B a time
    sample) and what waits for the next save (29 MB here), a third of what holding the
    stage to one save at the end costs (80 MB here, nearly three times the file's)."""
    source = tmp_path / "short.npz"
    _longer(guided_take, 20, creatures=64).save(source)
    grew, files = {}, {}
    for flush in (4 * 1024**2, 1024**4):
        found = []
        for frames in (1000, 3000):
            done = subprocess.run(
                [sys.executable, "-c", GROWTH, str(source), str(frames), str(flush),
                 str(tmp_path / "out.usdc")],
                capture_output=True, text=True, check=True,
            )  # fmt: skip
            found.append([float(x) for x in done.stdout.split()])
        grew[flush] = found[1][0] - found[0][0]
        files[flush] = found[1][1] - found[0][1]
    streamed, held = grew[4 * 1024**2], grew[1024**4]
    assert min(files.values()) > 25 and held > files[1024**4], (grew, files)
    assert streamed < 0.5 * held, (grew, files)


@pytest.mark.parametrize("skinned", [True, False])
def test_a_stop_while_writing_leaves_nothing(
    guided_take: Take, tmp_path: Path, skinned: bool, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Ctrl-C once the first chunk is in the file (saved): no file, no partial file, nor
    USD's own temporary file, in the folder."""
    monkeypatch.setattr(usd_layer, "FLUSH_BYTES", 1)
    monkeypatch.setattr(usd_layer, "REWRITE_SHARE", 0)  # a save after every chunk
    take = _longer(guided_take, 30, creatures=3)

    def stop(n: int) -> None:
        assert any(p.stat().st_size for p in tmp_path.iterdir())  # the first chunk saved
        raise KeyboardInterrupt

    write: Any = write_skinned_usd if skinned else write_usd
    with pytest.raises(KeyboardInterrupt):
        write(TakeChunks(take, 10), tmp_path / "crowd.usdc", progress=stop)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.usefixtures("ctrl_c_reaches_children")
def test_ctrl_c_while_a_crowd_usd_is_written_leaves_only_the_take(
    guided_take: Take, tmp_path: Path
) -> None:
    """A real export on a terminal, stopped once its bar shows frames written: exit 130,
    the take alone in the folder (no partial file, ours or USD's)."""
    take = tmp_path / "crowd.npz"
    _longer(guided_take, 3000, creatures=48).save(take)
    export_stopped_leaves_only_the_take(
        take, "crowd.usdc", r"write crowd\.usdc: .*\| ?([1-9]\d*)/3000"
    )
