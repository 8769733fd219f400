"""tools/soak.py's verdict: growth of the floor after warm-up, whatever a frame holds."""

from __future__ import annotations

import importlib.util
import re
import sys
from pathlib import Path
from types import ModuleType

import pytest

TOOLS = Path(__file__).resolve().parents[2] / "tools"

pytestmark = pytest.mark.skipif(not TOOLS.is_dir(), reason="needs the source tree")


def soak() -> ModuleType:
    spec = importlib.util.spec_from_file_location("soak", TOOLS / "soak.py")
    assert spec and spec.loader
    module = importlib.util.module_from_spec(spec)
    sys.modules["soak"] = module
    spec.loader.exec_module(module)
    return module


def test_a_flat_floor_after_warm_up_passes_with_spikes_and_a_creep_fails() -> None:
    tool = soak()
    warm = [(float(t), 100.0 + t) for t in range(0, 180, 30)]  # the build grows for real
    saw = [(float(t), 300.0 + 4.0 * (t // 30 % 2)) for t in range(180, 1800, 30)]
    ok, line = tool.verdict(warm + saw, 180.0, 5.0)
    assert ok, line
    assert line.startswith("PASS: resident memory after warm-up")
    creep = [(float(t), 300.0 + t / 200.0) for t in range(180, 1800, 30)]
    ok, line = tool.verdict(warm + creep, 180.0, 5.0)
    assert not ok
    assert line.startswith("FAIL:")
    slope = float(re.search(r"floor slope ([-+0-9.]+) MB/h", line).group(1))  # type: ignore[union-attr]
    assert slope == pytest.approx(18.0, rel=0.05)  # 1 MB per 200 s
    spikes = [(t, rss + (20.0 if t % 90 == 0 else 0.0)) for t, rss in saw]  # inside frames
    ok, line = tool.verdict(warm + spikes, 180.0, 5.0)
    assert ok, line
    assert "floor slope" in line and "peak 324.0 MB at 270 s (+24.0" in line
    assert not tool.verdict(warm, 180.0, 5.0)[0]  # nothing after the warm-up


def test_in_process_soak_times_frames_and_reports_the_medians_at_both_ends() -> None:
    import subprocess

    done = subprocess.run(
        [sys.executable, "-P", str(TOOLS / "soak.py"), "--scene", "octopus", "--in-process",
         "--minutes", "0.08", "--every", "1", "--warmup", "0"],
        capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert done.returncode == 0, done.stdout + done.stderr
    rows = [line.split() for line in done.stdout.splitlines() if line[:8].strip().isdigit()]
    assert len(rows) >= 2  # the start and the end (a slow machine may fit no more)
    assert all(float(row[3]) > 0 for row in rows)  # a frame's median time on every row
    ends = re.search(r"([0-9.]+) ms at the start, ([0-9.]+) ms at the end", done.stdout)
    assert ends and float(ends.group(1)) > 0 and float(ends.group(2)) > 0, done.stdout
