"""The rig benchmark runs and reports its columns (tiny sizes)."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import pytest

from ecs_tentacles.fur import rig

TOOL = Path(__file__).resolve().parents[2] / "tools" / "bench_rig.py"

pytestmark = pytest.mark.skipif(not TOOL.is_file(), reason="needs the source tree")


@pytest.mark.parametrize("backend", ["auto", "numpy"])
def test_bench_rig_prints_a_row_per_size(
    backend: str, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    spec = importlib.util.spec_from_file_location("bench_rig", TOOL)
    assert spec and spec.loader
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    monkeypatch.setattr(rig, "BACKEND", rig.BACKEND)  # the tool sets it: restore after
    argv = ["bench_rig.py", "--sizes", "50", "--repeats", "1", "--backend", backend, "--json"]
    monkeypatch.setattr(sys, "argv", argv)
    bench.main()
    out = capsys.readouterr().out
    for key in ("math_ms", "math_dynamic_ms", "system_ms", "system_dynamic_ms", "backend"):
        assert f'"{key}"' in out
    if backend == "numpy":
        assert '"backend": "numpy"' in out
