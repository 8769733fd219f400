"""tools/avoidance_report.py: a run reports the fields its doc promises (a short run)."""

from __future__ import annotations

import math

import pytest

from tests.tools.loader import TOOLS, load_tool

TOOL = TOOLS / "avoidance_report.py"


@pytest.mark.skipif(not TOOL.is_file(), reason="needs the source tree")
def test_a_run_reports_contacts_promotions_tiers_and_progress() -> None:
    report = load_tool("avoidance_report")
    row = report.run(2, False, 0.1, 0)
    assert (row["creatures"], row["avoidance"], row["frames"]) == (2, False, 6)
    assert row["contacts_a_frame"] == 0.0 and row["contact_frames"] == 0
    assert row["promotions"] == 0 and sum(row["tiers"].values()) == 2
    assert math.isfinite(row["progress_m"])
