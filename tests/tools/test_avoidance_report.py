"""tools/avoidance_report.py: a run reports the fields its doc promises (a short run)."""

from __future__ import annotations

import importlib.util
import math
import sys
from pathlib import Path

import pytest

TOOL = Path(__file__).resolve().parents[2] / "tools" / "avoidance_report.py"


@pytest.mark.skipif(not TOOL.is_file(), reason="needs the source tree")
def test_a_run_reports_contacts_promotions_tiers_and_progress() -> None:
    spec = importlib.util.spec_from_file_location("avoidance_report", TOOL)
    assert spec and spec.loader
    report = importlib.util.module_from_spec(spec)
    sys.modules["avoidance_report"] = report
    spec.loader.exec_module(report)
    row = report.run(2, False, 0.1, 0)
    assert (row["creatures"], row["avoidance"], row["frames"]) == (2, False, 6)
    assert row["contacts_a_frame"] == 0.0 and row["contact_frames"] == 0
    assert row["promotions"] == 0 and sum(row["tiers"].values()) == 2
    assert math.isfinite(row["progress_m"])
