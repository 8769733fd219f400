"""tools/reduced_pace.py: a short comparison runs one crowd reduced and full and reports
per-creature figures."""

from __future__ import annotations

import numpy as np
import pytest

from tests.tools.loader import TOOLS, load_tool

TOOL = TOOLS / "reduced_pace.py"


@pytest.mark.skipif(not TOOL.is_file(), reason="needs the source tree")
def test_a_short_comparison_runs_everyone_reduced_against_everyone_full() -> None:
    tool = load_tool("reduced_pace")
    reduced, full = (tool.run(4, 1.0, 0, 8.0, tier) for tier in (True, False))
    assert reduced["tiers"] == {"full": 0, "reduced": 4, "kinematic": 0}
    assert full["tiers"] == {"full": 4, "reduced": 0, "kinematic": 0}
    assert min(full["progress"]) > 0.0  # they crawl toward their goals
    result = tool.summary([(reduced, full)])
    assert result["creatures"] == 4
    assert 0.5 < result["progress_ratio"] < 1.5
    assert result["ratio_min"] <= result["ratio_max"] and np.isfinite(result["ratio_sd"])
    assert result["big_mantle_ratio"] is not None or result["small_mantle_ratio"] is not None
    # creatures of one body plan share a plan number, and their mantle
    plans, radii = np.asarray(full["plan"]), np.asarray(full["mantle_radius"])
    assert plans.tolist() == reduced["plan"]
    for plan in set(plans.tolist()):
        assert len(set(radii[plans == plan].tolist())) == 1
    assert result["plans"] == len(set(plans.tolist())) >= 2
    assert result["plan_ratio_min"] <= result["progress_ratio"] <= result["plan_ratio_max"]
    assert np.isfinite(result["within_plan_sd"])


@pytest.mark.skipif(not TOOL.is_file(), reason="needs the source tree")
def test_another_reduced_model_is_used_by_the_reduced_run() -> None:
    tool = load_tool("reduced_pace")
    model = {"links": 1.0, "rate": 1.0, "gain": 1.0, "damping": 1.0}
    # every link at the full rate with the full gains: the full creature again
    try:
        reduced, full = (tool.run(4, 1.0, 0, 8.0, tier, None, model) for tier in (True, False))
    finally:
        tool.use_model(None)  # the rest of this process's tests: the default model
    ratio = np.asarray(reduced["progress"]) / np.asarray(full["progress"])
    assert np.allclose(ratio, 1.0, atol=0.05)
    # and the default model differs from it, and is the one a later run gets back
    default = tool.run(4, 1.0, 0, 8.0, True)
    assert not np.allclose(default["progress"], reduced["progress"], atol=1e-4)


@pytest.mark.skipif(not TOOL.is_file(), reason="needs the source tree")
def test_a_servo_setting_runs_default_octopuses_with_those_servos() -> None:
    tool = load_tool("reduced_pace")
    assert tool.servo_list("25/0.5,100/2") == [(25.0, 0.5), (100.0, 2.0)]
    with pytest.raises(ValueError, match="'25'"):
        tool.servo_list("25,100/2")
    rows = tool.servo_sweep([(25.0, 5.0)], 2, 1.0, [0], 8.0)
    assert len(rows) == 1 and (rows[0]["strength"], rows[0]["damping"]) == (25.0, 5.0)
    assert rows[0]["tiers_reduced_run"] == [{"full": 0, "reduced": 2, "kinematic": 0}]
    assert 0.5 < rows[0]["progress_ratio"] < 1.5
