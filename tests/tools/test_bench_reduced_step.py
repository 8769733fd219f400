"""tools/bench_reduced_step.py on a small crowd: the reduced step against MuJoCo alone."""

from __future__ import annotations

import json

import pytest

from tests.tools.loader import TOOLS, load_tool

pytestmark = pytest.mark.skipif(not TOOLS.is_dir(), reason="needs the source tree")


def test_the_reduced_step_and_its_kinematics_are_timed(capsys: pytest.CaptureFixture[str]) -> None:
    tool = load_tool("bench_reduced_step")
    argv = ["--crowd", "12", "--varied", "--warmup", "3", "--repeats", "2", "--json"]
    assert tool.main(argv) == 0
    result = json.loads(capsys.readouterr().out)
    assert result["reduced"] == 12  # past the full budget (8): all within the reduced one
    assert 0 < result["bare_ms"] and 0 < result["framework_ms"]
    assert result["ratio"] == pytest.approx(result["framework_ms"] / result["bare_ms"])
    assert result["show_kernel_us_per_reduced"] > 0 and result["show_mujoco_us_per_reduced"] > 0


def test_a_bad_count_is_refused_by_name(capsys: pytest.CaptureFixture[str]) -> None:
    tool = load_tool("bench_reduced_step")
    with pytest.raises(SystemExit) as exit_info:
        tool.main(["--repeats", "0"])
    assert exit_info.value.code == 2
    assert "--repeats must be >= 1, got 0" in capsys.readouterr().err
