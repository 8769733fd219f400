"""tools/numba_warmup.py: the kernels compiled ahead of a test run are the ones a later
process loads from numba's cache instead of compiling, and the list it compiles names
the package's kernels as they are."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

from numba.core import types

from tests.tools.loader import load_tool

TOOL = Path(__file__).resolve().parents[2] / "tools" / "numba_warmup.py"
KERNEL = "ecs_tentacles.numeric.quaternion_kernels:matrices"
# a fresh process calls the kernel as the package does and says how it got it
CALL = """
import numpy as np
from ecs_tentacles.numeric.quaternion_kernels import matrices
quat = np.tile([1.0, 0.0, 0.0, 0.0], (3, 1))
matrices(quat, np.empty((3, 3, 3)))
print(sum(matrices.stats.cache_hits.values()), sum(matrices.stats.cache_misses.values()))
"""


def _hits_and_misses(env: dict[str, str]) -> list[int]:
    done = subprocess.run(
        [sys.executable, "-c", CALL], env=env, capture_output=True, text=True, check=True
    )
    return [int(x) for x in done.stdout.split()]


def test_a_kernel_compiled_ahead_is_loaded_not_compiled_by_the_next_process(
    tmp_path: Path,
) -> None:
    """Compiled by the tool for the signature the list holds, the kernel is a cache hit
    in the next process (the same cache file, key and source stamp); without the tool,
    that process compiles it (a miss)."""
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "cold")}
    assert _hits_and_misses(env) == [0, 1]

    listed = json.loads(load_tool("numba_warmup").LIST.read_text())
    (tmp_path / "list.json").write_text(json.dumps({KERNEL: listed[KERNEL]}))
    env["NUMBA_CACHE_DIR"] = str(tmp_path / "warm")
    (tmp_path / "claims").mkdir()
    done = subprocess.run(
        [sys.executable, str(TOOL), "compile", "--claims", str(tmp_path / "claims"),
         "--list", str(tmp_path / "list.json")],
        env=env, capture_output=True, text=True, check=True,
    )  # fmt: skip
    assert done.stdout.startswith("1 compiled or cached, 0 stale"), done.stdout
    assert _hits_and_misses(env) == [1, 0]


def test_processes_sharing_claims_compile_each_kernel_once(tmp_path: Path) -> None:
    """A second process with the same claims folder takes none of the kernels the
    first took; a signature whose kernel is gone counts as stale."""
    tool = load_tool("numba_warmup")
    listed = json.loads(tool.LIST.read_text())
    listed = {KERNEL: listed[KERNEL], "ecs_tentacles.numeric.gone:k": ["(int64,)"]}
    assert tool.compile_listed(listed, tmp_path) == (1, 1)
    assert tool.compile_listed(listed, tmp_path) == (0, 0)


def test_the_list_names_the_packages_kernels_and_types_that_read_back() -> None:
    """Every kernel the list names is a cached kernel of the package (a renamed or moved
    kernel fails here until `python tools/numba_warmup.py record` lists it anew), and
    every signature reads back as numba's types."""
    tool = load_tool("numba_warmup")
    listed = json.loads(tool.LIST.read_text())
    found = {}
    for module in tool.kernel_modules():
        found.update(tool.dispatchers(module))
    assert set(listed) <= set(found), sorted(set(listed) - set(found))
    assert len(listed) >= 0.75 * len(found)  # the suite calls most kernels
    for signatures in listed.values():
        for signature in signatures:
            assert all(isinstance(t, types.Type) for t in tool.parse(signature)), signature
