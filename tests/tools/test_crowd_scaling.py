"""tools/crowd_scaling.py on tiny crowds: the CSV's columns and rows, a real PNG."""

from __future__ import annotations

import csv
import os
from pathlib import Path

import pytest
from PIL import Image

from tests.tools.test_tools import TOOLS, _load

pytestmark = pytest.mark.skipif(not TOOLS.is_dir(), reason="needs the source tree")

COLUMNS = [
    "creatures",
    "threads",
    "compiles",
    "bodies",
    "build_s",
    "build_s_per_creature",
    "frame_ms",
    "frame_ms_per_creature",
    "physics_ms",
    "raw_mujoco_ms",
    "overhead_ratio",
    "realtime_factor",
    "rss_mb",
    "error",
]


def test_tiny_sizes_write_the_csv_and_the_plot(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scaling = _load("crowd_scaling")
    assert scaling.main(["--sizes", "1,2", "--frames", "2", "--out", str(tmp_path / "s")]) == 0
    with open(tmp_path / "s.csv", newline="") as handle:
        reader = csv.DictReader(handle)
        rows = list(reader)
    assert reader.fieldnames == COLUMNS
    all_threads = os.cpu_count() or 1
    runs = {(n, t) for n in (1, 2) for t in {1, all_threads}}
    assert {(int(r["creatures"]), int(r["threads"])) for r in rows} == runs
    assert len(rows) == len(runs)
    for row in rows:
        assert row["error"] == ""
        assert float(row["build_s_per_creature"]) == pytest.approx(
            float(row["build_s"]) / int(row["creatures"])
        )
        assert float(row["frame_ms_per_creature"]) == pytest.approx(
            float(row["frame_ms"]) / int(row["creatures"])
        )
        assert float(row["overhead_ratio"]) > 0 and float(row["rss_mb"]) > 0
    png = tmp_path / "s.png"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    with Image.open(png) as image:
        assert image.format == "PNG" and image.size == (1100, 462)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.csv", "s.png"]
    err = capsys.readouterr().err
    assert f"[1/{len(runs)}] 1 creatures, 1 threads ..." in err and "wrote " in err


def test_a_failed_run_keeps_its_error_line() -> None:
    scaling = _load("crowd_scaling")
    row = scaling.bench_once(1, 1, frames=0, seed=0, timeout=60)
    assert row == {
        "creatures": 1,
        "threads": 1,
        "error": "error: argument --frames: must be >= 1, got 0 (see ecs-tentacles bench --help)",
    }
