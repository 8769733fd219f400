"""tools/crowd_scaling.py on tiny crowds: the CSV's columns and rows, a real PNG."""

from __future__ import annotations

import csv
from pathlib import Path

import pytest
from PIL import Image

from tests.tools.loader import TOOLS, load_tool

pytestmark = pytest.mark.skipif(not TOOLS.is_dir(), reason="needs the source tree")

COLUMNS = [
    "creatures",
    "lod",
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
    "full",
    "reduced",
    "kinematic",
    "promotions",
    "error",
]


def test_tiny_sizes_write_the_csv_and_the_plot(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scaling = load_tool("crowd_scaling")
    argv = ["--sizes", "1,2", "--frames", "2", "--threads", "1", "--warmup", "2"]
    argv += ["--out", str(tmp_path / "s")]
    assert scaling.main(argv) == 0
    with open(tmp_path / "s.csv", newline="") as handle:
        reader = csv.DictReader(handle)
        rows = list(reader)
    assert reader.fieldnames == COLUMNS
    runs = {(n, lod) for n in (1, 2) for lod in ("on", "off")}
    assert {(int(r["creatures"]), r["lod"]) for r in rows} == runs
    assert len(rows) == len(runs) and {r["threads"] for r in rows} == {"1"}
    for row in rows:
        assert row["error"] == ""
        # tiny crowds fit the full budget: everyone full, lod on or off
        tiers = [int(row[t]) for t in ("full", "reduced", "kinematic")]
        assert tiers == [int(row["creatures"]), 0, 0] and row["promotions"] == "0"
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
    assert f"[1/{len(runs)}] 1 creatures, lod on, 1 threads ..." in err and "wrote " in err


def test_a_failed_run_keeps_its_error_line() -> None:
    scaling = load_tool("crowd_scaling")
    row = scaling.bench_once(1, 1, frames=0, seed=0, timeout=60)
    assert row == {
        "creatures": 1,
        "lod": "on",
        "threads": 1,
        "error": "error: argument --frames: must be >= 1, got 0 (see ecs-tentacles bench --help)",
    }


def test_a_run_past_its_timeout_is_an_error_row(tmp_path: Path) -> None:
    scaling = load_tool("crowd_scaling")
    row = scaling.bench_once(64, 1, frames=100000, seed=0, timeout=0.5, lod="off")
    assert row == {
        "creatures": 64,
        "lod": "off",
        "threads": 1,
        "error": "timed out after 0.5 s (--timeout)",
    }
    rows = [row, {**row, "lod": "on"}]
    scaling.write_csv(rows, tmp_path / "t.csv")
    scaling.plot(rows, tmp_path / "t.png")  # a plot with no finished run still draws
    assert (tmp_path / "t.png").read_bytes()[:4] == b"\x89PNG"
