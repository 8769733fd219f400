"""tools/step_cache_cost.py on a tiny crowd: every system timed with and without stepping."""

from __future__ import annotations

import json

import pytest

from tests.tools.loader import TOOLS, load_tool, refused

pytestmark = pytest.mark.skipif(not TOOLS.is_dir(), reason="needs the source tree")


def test_every_system_is_timed_both_ways_and_only_the_stepped_run_moves(
    capsys: pytest.CaptureFixture[str],
) -> None:
    tool = load_tool("step_cache_cost")
    argv = ["--crowd", "2", "--threads", "1", "--frames", "3", "--warmup", "5", "--repeat", "1"]
    assert tool.main([*argv, "--json"]) == 0
    out, err = capsys.readouterr()
    result = json.loads(out)
    stepped, still = (result["us_per_frame"][mode] for mode in tool.MODES)
    assert set(stepped) == set(still)
    assert {"physics", "physics_health", "rig", "(systems but physics)"} <= set(stepped)
    assert all(value > 0 for value in [*stepped.values(), *still.values()])
    assert result["moved_m"]["stepped"] > 0.0 and result["moved_m"]["not stepped"] == 0.0
    assert "run 1/1: not stepped" in err


def test_a_bad_count_is_refused_by_name(capsys: pytest.CaptureFixture[str]) -> None:
    assert "--frames must be >= 1, got 0" in refused("step_cache_cost", ["--frames", "0"], capsys)
