"""tools/bench_batch_step.py on a small crowd: MuJoCo's batch steps the reduced tier's
captured rows, overlays and all, to the loop's bits, and both ways are timed."""

from __future__ import annotations

import json

import pytest

from tests.tools.loader import TOOLS, load_tool, refused

pytestmark = pytest.mark.skipif(not TOOLS.is_dir(), reason="needs the source tree")
pytest.importorskip("mujoco.batch", reason="MuJoCo 4.0 or later")


def test_the_batch_ends_every_reduced_row_where_the_loop_does(
    capsys: pytest.CaptureFixture[str],
) -> None:
    tool = load_tool("bench_batch_step")
    argv = ["--crowd", "12", "--warmup", "20", "--frames", "3", "--repeat", "2", "--json"]
    assert tool.main(argv) == 0
    result = json.loads(capsys.readouterr().out)
    assert result["frames"] == 3 and result["reduced_rows"] == 12  # past the full budget
    assert result["rows_compared"] == 36
    assert result["rows_bit_identical"] == result["rows_compared"]
    assert result["loop_ms"] > 0 and result["batch_ms"] > 0
    assert result["batch_over_loop"] == pytest.approx(result["batch_ms"] / result["loop_ms"])


def test_a_crowd_within_the_full_budget_is_refused_in_a_line(
    capsys: pytest.CaptureFixture[str],
) -> None:
    tool = load_tool("bench_batch_step")
    assert tool.main(["--crowd", "2", "--warmup", "1", "--frames", "1", "--repeat", "1"]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "no creature of 2 was stepped REDUCED" in err


def test_a_bad_count_is_refused_by_name(capsys: pytest.CaptureFixture[str]) -> None:
    assert "--repeat: must be >= 1, got 0" in refused("bench_batch_step", ["--repeat", "0"], capsys)
