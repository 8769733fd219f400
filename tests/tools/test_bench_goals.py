"""The goals benchmark runs and reports a row per path length (tiny sizes)."""

from __future__ import annotations

import json
import sys

import pytest

from tests.tools.loader import TOOLS, load_tool

pytestmark = pytest.mark.skipif(not (TOOLS / "bench_goals.py").is_file(), reason="source tree")


def test_bench_goals_prints_a_row_per_path_length(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    bench = load_tool("bench_goals")
    argv = ["bench_goals.py", "--creatures", "2", "--goals", "4,8", "--repeats", "1", "--json"]
    monkeypatch.setattr(sys, "argv", argv)
    bench.main()
    rows = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert [(row["creatures"], row["goals"]) for row in rows] == [(2, 4), (2, 8)]
    assert {"build_s", "first_frame_ms", "unchanged_frame_ms"} <= rows[0].keys()
    assert rows[1]["first_frame_ms_ratio"] > 0
