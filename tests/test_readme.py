"""The README's Python examples run as written (in order, sharing one namespace)."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest

README = Path(__file__).resolve().parents[1] / "README.md"


@pytest.mark.skipif(not README.exists(), reason="needs the source tree")
def test_readme_python_blocks_run() -> None:
    blocks = re.findall(r"```python\n(.*?)```", README.read_text(), flags=re.S)
    assert len(blocks) >= 2
    namespace: dict[str, object] = {}
    for block in blocks:
        exec(compile(block, str(README), "exec"), namespace)
    world: Any = namespace["world"]
    assert world.schedule.names == ["wave", "physics", "physics_sync"]
    before = world.time
    world.step(1)
    assert (world.motors.target[:, 1] == 0.3 * np.sin(2 * np.pi * before)).all()
    world.close()
