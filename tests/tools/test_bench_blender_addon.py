"""The add-on's benchmark imports a take in Blender and reports its figures (a tiny take;
skipped without bpy, as the add-on's own tests)."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest

from ecs_tentacles.cli import main
from tests.blender_addon.conftest import BLENDER, needs_blender
from tests.tools.loader import TOOLS, load_tool

pytestmark = [
    pytest.mark.skipif(not (TOOLS / "bench_blender_addon.py").is_file(), reason="source tree"),
    needs_blender,
]


def test_bench_blender_addon_reports_time_memory_and_where_the_mantles_are(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    take = tmp_path / "four.npz"
    argv = ["bake", "thesis_four_by_six", "--seconds", "0.3", "--fps", "30", "--quiet"]
    assert main([*argv, "--out", str(take)]) == 0
    capsys.readouterr()
    bench = load_tool("bench_blender_addon")
    argv = ["bench_blender_addon.py", str(take), "--blender", BLENDER, "--sample", "3", "--json"]
    monkeypatch.setattr(sys, "argv", argv)
    bench.main()
    row = json.loads(capsys.readouterr().out.splitlines()[-1])
    assert (row["creatures"], row["frames"], row["sampled"], row["moving"]) == (4, 10, 3, 3)
    assert row["import_s"] > 0 and row["blender_peak_gb"] > 0.1
    assert row["mantle_error_mm"] < 0.01
