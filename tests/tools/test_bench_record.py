"""The recording benchmark runs and reports a row per crowd size (tiny sizes)."""

from __future__ import annotations

import json
import sys

import pytest

from tests.tools.loader import TOOLS, load_tool

pytestmark = pytest.mark.skipif(not (TOOLS / "bench_record.py").is_file(), reason="source tree")


def test_bench_record_prints_a_row_per_crowd(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    bench = load_tool("bench_record")
    argv = ["bench_record.py", "--creatures", "1,2", "--frames", "2", "--json", "--bakes"]
    monkeypatch.setattr(sys, "argv", [*argv, "--seconds", "0.2"])
    bench.main()
    rows = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert [(row["creatures"], row["bodies"]) for row in rows] == [(1, 81), (2, 162)]
    assert all(row["recorded_frame_calls"] > 0 for row in rows)
    assert all(row["live_frame_ms"] > 0 and row["recorded_frame_ms"] > 0 for row in rows)
    assert {"finish_ms", "frame_mb", "bake_all_s", "bake_recorded_frame_ms"} <= rows[0].keys()
