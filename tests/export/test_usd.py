"""USD export: the stage passes USD's validators and holds the take's values."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

from ecs_tentacles.export.names import unique_path
from ecs_tentacles.export.usd import build_stage, write_usd
from ecs_tentacles.export.usd_validation import usd_problems
from ecs_tentacles.take import Take

pxr = pytest.importorskip("pxr", reason="USD export needs usd-core (the usd / dev extras)")
from pxr import Gf, Usd, UsdGeom  # noqa: E402


@pytest.mark.parametrize("suffix", [".usda", ".usdc", ".usd"])
def test_the_stage_passes_the_usd_validators(
    guided_take: Take, tmp_path: Path, suffix: str
) -> None:
    path = tmp_path / f"take{suffix}"
    write_usd(guided_take, path)
    assert usd_problems(path) == []


def _xform_values(prim: Any, frame: int) -> tuple[np.ndarray, np.ndarray]:
    translate = prim.GetAttribute("xformOp:translate").Get(frame)
    orient: Gf.Quatf = prim.GetAttribute("xformOp:orient").Get(frame)
    quat = [orient.GetReal(), *orient.GetImaginary()]
    return np.array(translate), np.array(quat, dtype=np.float32)


def test_reopened_values_equal_the_take_at_sampled_time_codes(
    guided_take: Take, tmp_path: Path
) -> None:
    take = guided_take
    write_usd(take, tmp_path / "take.usda")
    stage = Usd.Stage.Open(str(tmp_path / "take.usda"))
    assert UsdGeom.GetStageUpAxis(stage) == "Z"
    assert UsdGeom.GetStageMetersPerUnit(stage) == 1.0
    assert stage.GetTimeCodesPerSecond() == stage.GetFramesPerSecond() == 30.0
    assert (stage.GetStartTimeCode(), stage.GetEndTimeCode()) == (0.0, take.frames - 1)
    assert stage.GetDefaultPrim().GetPath() == "/World"
    cache = UsdGeom.XformCache()
    for frame in (0, 3, take.frames - 1):
        cache.SetTime(frame)
        for index, body in enumerate(take.header["bodies"]):
            prim = stage.GetPrimAtPath(f"/World/{unique_path(body['name'])}")
            assert prim.GetTypeName() == "Xform"
            translate, quat = _xform_values(prim, frame)
            np.testing.assert_array_equal(translate, take.pos[frame, index])
            np.testing.assert_array_equal(quat, take.quat[frame, index])
            world = cache.GetLocalToWorldTransform(prim).ExtractTranslation()
            np.testing.assert_allclose(world, take.pos[frame, index], atol=1e-7)
        curves = UsdGeom.BasisCurves(stage.GetPrimAtPath("/World/octo/octo_fur/octo_guides"))
        points = np.array(curves.GetPointsAttr().Get(frame))
        np.testing.assert_array_equal(points, take.tracks["guide_points"][frame].reshape(-1, 3))
        widths = np.array(curves.GetWidthsAttr().Get(frame))
        np.testing.assert_array_equal(widths, take.tracks["guide_widths"][frame].reshape(-1))
    assert list(curves.GetCurveVertexCountsAttr().Get()) == [4, 4, 4]
    assert curves.GetTypeAttr().Get() == "linear"
    assert curves.GetWidthsInterpolation() == "vertex"


def test_geometry_axes_radii_heights_goals_and_suckers(guided_take: Take, tmp_path: Path) -> None:
    stage = build_stage(guided_take)
    mantle = UsdGeom.Cylinder(stage.GetPrimAtPath("/World/octo/octo_mantle/octo_mantle_geom"))
    assert (mantle.GetAxisAttr().Get(), mantle.GetRadiusAttr().Get()) == ("Z", 0.15)
    assert mantle.GetHeightAttr().Get() == 0.2
    tip = UsdGeom.Capsule(
        stage.GetPrimAtPath("/World/octo/octo_tentacles/octo_t2/octo_t2_link3/octo_t2_link3_geom")
    )
    body = guided_take.header["bodies"][guided_take.body("octo/tentacles/t2/link3")]
    assert tip.GetAxisAttr().Get() == "X"
    assert (tip.GetRadiusAttr().Get(), tip.GetHeightAttr().Get()) == (
        body["radius"],
        body["length"],
    )
    assert body["length"] == pytest.approx(0.07 * 0.3) and body["radius"] == pytest.approx(0.0075)
    extent = [list(v) for v in tip.GetExtentAttr().Get()]
    np.testing.assert_allclose(extent, [[-0.018, -0.0075, -0.0075], [0.018, 0.0075, 0.0075]])
    goal = stage.GetPrimAtPath("/World/octo/octo_goals/octo_goal0")
    assert goal.GetTypeName() == "Xform"
    assert list(goal.GetAttribute("xformOp:translate").Get()) == [1.0, 0.0, 0.0]
    assert goal.GetAttribute("ecs:radius").Get() == pytest.approx(0.2)
    assert UsdGeom.Imageable(goal).ComputeVisibility(5) == "inherited"
    sucker = stage.GetPrimAtPath(
        "/World/octo/octo_tentacles/octo_t0/octo_t0_link3/octo_t0_link3_sucker0"
    )
    assert sucker.GetAttribute("ecs:attached").Get(0) is False
    assert [p.GetName() for p in stage.GetPrimAtPath("/World/octo").GetChildren()] == [
        "octo_mantle",
        "octo_tentacles",
        "octo_goals",
        "octo_fur",
    ]


def test_usdc_and_usda_hold_the_same_samples(guided_take: Take, tmp_path: Path) -> None:
    for suffix in (".usda", ".usdc"):
        write_usd(guided_take, tmp_path / f"take{suffix}")
    text, crate = (Usd.Stage.Open(str(tmp_path / f"take{s}")) for s in (".usda", ".usdc"))
    path = "/World/octo/octo_tentacles/octo_t1/octo_t1_link2"
    for frame in (0, 6):
        a = _xform_values(text.GetPrimAtPath(path), frame)
        b = _xform_values(crate.GetPrimAtPath(path), frame)
        np.testing.assert_array_equal(a[0], b[0])
        np.testing.assert_array_equal(a[1], b[1])
    assert (tmp_path / "take.usdc").read_bytes()[:8] == b"PXR-USDC"


def test_reached_goals_turn_invisible_and_suckers_switch(guided_take: Take) -> None:
    from dataclasses import replace

    goals = guided_take.tracks["goal_active"].copy()
    goals[3:, 0] = False  # reached at frame 3
    suckers = guided_take.sucker_attached.copy()
    suckers[:, 1] = [False, False, True, True, False, False, False]
    stage = build_stage(
        replace(
            guided_take,
            tracks={**guided_take.tracks, "goal_active": goals},
            sucker_attached=suckers,
        )
    )
    goal = UsdGeom.Imageable(stage.GetPrimAtPath("/World/octo/octo_goals/octo_goal0"))
    assert [goal.ComputeVisibility(f) for f in (0, 2, 3, 6)] == [
        "inherited",
        "inherited",
        "invisible",
        "invisible",
    ]
    attached = stage.GetPrimAtPath(
        "/World/octo/octo_tentacles/octo_t1/octo_t1_link3/octo_t1_link3_sucker0"
    ).GetAttribute("ecs:attached")
    assert [attached.Get(f) for f in range(7)] == [False, False, True, True, False, False, False]
