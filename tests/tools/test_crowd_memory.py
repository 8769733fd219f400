"""tools/crowd_memory.py on a tiny crowd: resident figures, the arrays found, bad input."""

from __future__ import annotations

import json

import pytest

from tests.tools.loader import TOOLS, load_tool, refused

pytestmark = pytest.mark.skipif(not TOOLS.is_dir(), reason="needs the source tree")


def test_a_small_crowd_reports_its_memory_and_where_the_arrays_are(
    capsys: pytest.CaptureFixture[str],
) -> None:
    tool = load_tool("crowd_memory")
    assert tool.main(["--crowd", "3", "--frames", "2", "--top", "40", "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert result["crowd"] == 3 and result["frames"] == 2
    assert 0 < result["built_rss_mib"] <= result["peak_mib"]
    assert sum(result["tiers"].values()) == 3
    labels = [label for label, _, _ in result["arrays_mb"]]
    # resident (touched pages) and allocated megabytes; the state is written at the build
    state = next(row for row in result["arrays_mb"] if row[0].endswith("batches.[0].state"))
    assert 0 < state[1] and 0 < state[2]
    assert any(label.endswith("batches.[0].state") for label in labels)  # the physics state
    assert any("health.saved" in label for label in labels)


def test_bad_sizes_are_refused(capsys: pytest.CaptureFixture[str]) -> None:
    assert "--crowd must be >= 1, got 0" in refused("crowd_memory", ["--crowd", "0"], capsys)
