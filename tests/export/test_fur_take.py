"""Fur guides in takes and USD, from a real furry creature (needs the fur package)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from ecs_tentacles.export.usd import write_usd
from ecs_tentacles.fur.stores import FurData
from ecs_tentacles.record.systems.record import Record
from ecs_tentacles.world import World

hooks = pytest.importorskip("ecs_tentacles.fur.hooks", reason="the fur package is not here yet")

FURRY = {
    "version": 1,
    "creatures": [
        {
            "name": "cat",
            "position": [0, 0],
            "tentacles": {"count": 3, "links": 4},
            "fur": {"preset": "cat"},
        }
    ],
}


def test_recording_poses_guides_at_frame_0_and_follows_the_rig(tmp_path: Path) -> None:
    recorded, plain = World.from_scene(FURRY), World.from_scene(FURRY)
    system = Record()
    recorded.add_system(system)
    take = system.take()
    points = take.tracks["guide_points"]
    assert np.abs(points[0]).max() > 0.1
    recorded.step(4)
    plain.step(4)
    np.testing.assert_array_equal(
        recorded.resource(FurData).curves, plain.resource(FurData).curves
    )  # no side effects
    take = system.take()
    curves = hooks.guide_curves(plain)
    points, widths = take.tracks["guide_points"], take.tracks["guide_widths"]
    np.testing.assert_array_equal(points[4], curves.points)
    np.testing.assert_array_equal(widths[4, :, 0], curves.width)
    assert take.header["guides"]["creatures"] == [0] * len(curves.points)
    write_usd(take, tmp_path / "cat.usda")
    pxr = pytest.importorskip("pxr")
    stage = pxr.Usd.Stage.Open(str(tmp_path / "cat.usda"))
    guides = pxr.UsdGeom.BasisCurves(stage.GetPrimAtPath("/World/cat/cat_fur/cat_guides"))
    assert len(guides.GetCurveVertexCountsAttr().Get()) == len(curves.points)
    recorded.close()
    plain.close()
