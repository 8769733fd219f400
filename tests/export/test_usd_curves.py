"""Fur guides in the skinned USD ride their creature's mantle: guides that do not sway are
written once, guides that do every frame, and every point is where the take has it."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from ecs_tentacles.export.skinned_usd import write_skinned_usd
from ecs_tentacles.export.usd_curves import TOLERANCE, Held
from ecs_tentacles.take.stream import open_take

pxr = pytest.importorskip("pxr", reason="USD export needs usd-core (the usd / dev extras)")
from pxr import Usd, UsdGeom  # noqa: E402


def test_still_guides_are_written_once_and_every_point_stays_within_the_tolerance(
    replay_take: Path, tmp_path: Path
) -> None:
    """Stiff fur (the hedgehog and bird presets) rides the mantle without swaying (in its
    mantle's frame it moves only by the take's 0.1 mm rounding): one sample each; a
    cat's sways: a sample every frame. At every frame, through the folder that follows
    the mantle, every guide point is within 0.5 mm of the take's."""
    usd = tmp_path / "crowd.usdc"
    with open_take(replay_take) as source:
        write_skinned_usd(source, usd)
        header = source.header
        owners = np.asarray(header["guides"]["creatures"])
        names = [c["name"] for c in header["creatures"]]
        stage = Usd.Stage.Open(str(usd))
        curves = {
            owner: UsdGeom.BasisCurves(
                stage.GetPrimAtPath(
                    f"/World/{names[owner]}/{names[owner]}_fur/{names[owner]}_guides"
                )
            )
            for owner in sorted(set(owners.tolist()))
        }
        worst = 0.0
        for first, chunk in source.chunks():
            for row in range(chunk.frames):
                frame = first + row
                cache = UsdGeom.XformCache(frame)
                for owner, prim in curves.items():
                    matrix = np.array(cache.GetLocalToWorldTransform(prim.GetPrim()))
                    local = np.array(prim.GetPointsAttr().Get(frame), dtype=np.float64)
                    world = local @ matrix[:3, :3] + matrix[3, :3]
                    expected = chunk.tracks["guide_points"][row, owners == owner].reshape(-1, 3)
                    worst = max(worst, float(np.abs(world - expected).max()))
    samples = {owner: prim.GetPointsAttr().GetNumTimeSamples() for owner, prim in curves.items()}
    scene = json.loads(replay_take.with_suffix(".json").read_text())
    presets = {owner: scene["creatures"][owner]["fur"]["preset"] for owner in curves}
    assert sorted(set(presets.values())) == ["bird", "cat", "hedgehog"]
    for owner, preset in presets.items():
        assert samples[owner] == (header["frames"] if preset == "cat" else 1), (presets, samples)
    assert worst < TOLERANCE


def test_held_samples_keep_linear_interpolation_within_the_limit() -> None:
    """A value that creeps (below the limit a frame) is written where it has moved past
    the limit, with the frame before: between written samples USD's linear interpolation
    of the written values is within twice the limit of every frame's value."""
    held = Held(0.5)
    values = np.concatenate([np.zeros(5), np.linspace(0.0, 3.0, 10), np.full(5, 3.0)])
    written = [s for f, v in enumerate(values) for s in held.keep(f, np.array([v]))]
    frames = np.array([f for f, _ in written])
    kept = np.array([v[0] for _, v in written])
    assert len(written) < len(values)
    between = np.interp(np.arange(len(values)), frames, kept)
    assert np.abs(between - values).max() <= 2 * 0.5
