"""The glb benchmark runs and reports a row per form (a tiny crowd, no Blender)."""

from __future__ import annotations

import json
import sys

import pytest

from tests.tools.loader import TOOLS, load_tool

pytestmark = pytest.mark.skipif(not (TOOLS / "bench_glb.py").is_file(), reason="source tree")


def test_bench_glb_prints_a_row_per_form(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    bench = load_tool("bench_glb")
    argv = ["bench_glb.py", "--creatures", "2", "--seconds", "0.2", "--json"]
    monkeypatch.setattr(sys, "argv", argv)
    bench.main()
    rows = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert [(row["form"], row["creatures"], row["frames"]) for row in rows] == [
        ("skinned", 2, 13),
        ("rigid", 2, 13),
    ]
    for row in rows:
        assert row["export_s"] > 0 and row["export_peak_gb"] > 0 and row["glb_mb"] > 0
        assert 0 <= row["counted_over_pct"] < 40  # the count is never less than the file
        assert row["blender_estimate_gb"] >= 0.34 and "blender_s" not in row
