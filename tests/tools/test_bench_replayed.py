"""tools/bench_replayed.py on a tiny crowd: the split of a frame per replayed creature."""

from __future__ import annotations

import json

import pytest

from tests.tools.loader import TOOLS, load_tool, refused

pytestmark = pytest.mark.skipif(not TOOLS.is_dir(), reason="needs the source tree")


def test_every_part_is_timed_per_replayed_creature(capsys: pytest.CaptureFixture[str]) -> None:
    tool = load_tool("bench_replayed")
    argv = ["--crowd", "9", "--reduced", "1", "--frames", "2", "--warmup", "2", "--threads", "1"]
    assert tool.main([*argv, "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert result["replayed"] == 8  # 9 creatures (past the full budget), one reduced
    assert {"physics", "lod_replay", "physics_sync", "rig"} <= set(result["systems"])
    assert {label for label, _, _ in tool.PARTS} == set(result["parts"])
    replay = result["parts"]["replay_advance"]
    assert replay["ms"] > 0 and replay["us_per_replayed"] == pytest.approx(1000 * replay["ms"] / 8)
    assert 0 < result["frame_less_stepping_ms"] < result["frame_ms"]
    assert 0 < replay["cpu_us_per_replayed"] and 0 < result["cpu_us_per_replayed_less_stepping"]


def test_a_bad_count_is_refused_by_name(capsys: pytest.CaptureFixture[str]) -> None:
    assert "--frames must be >= 1, got 0" in refused("bench_replayed", ["--frames", "0"], capsys)
