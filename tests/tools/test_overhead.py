"""tools/overhead.py on tiny crowds: interleaved runs, each setting's median and its runs."""

from __future__ import annotations

import json
import statistics

import pytest

from tests.tools.loader import TOOLS, load_tool, refused

pytestmark = pytest.mark.skipif(not TOOLS.is_dir(), reason="needs the source tree")


def test_runs_are_interleaved_and_each_setting_gets_its_median(
    capsys: pytest.CaptureFixture[str],
) -> None:
    tool = load_tool("overhead")
    argv = ["--sizes", "1,2", "--threads", "1", "--repeat", "2", "--frames", "2"]
    assert tool.main([*argv, "--warmup", "2", "--json"]) == 0
    out, err = capsys.readouterr()
    results = json.loads(out)
    assert [(r["creatures"], r["threads"]) for r in results] == [(1, 1), (2, 1)]
    for r in results:
        assert len(r["overhead_ratios"]) == 2 and all(x > 0 for x in r["overhead_ratios"])
        assert r["median"] == statistics.median(r["overhead_ratios"])
        assert r["within_target"] == (r["median"] <= tool.TARGET) and r["error"] == ""
    order = [line.split(": ")[1] for line in err.splitlines() if line.startswith("run ")]
    assert order == ["1 creatures, 1 threads", "2 creatures, 1 threads"] * 2


def test_a_bad_repeat_is_refused(capsys: pytest.CaptureFixture[str]) -> None:
    assert "--repeat and --frames must be >= 1" in refused("overhead", ["--repeat", "0"], capsys)
