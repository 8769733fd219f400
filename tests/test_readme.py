"""The README's Python examples run as written (in order, sharing one namespace)."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from ecs_tentacles.world import World

README = Path(__file__).resolve().parents[1] / "README.md"


@pytest.mark.skipif(not README.exists(), reason="needs the source tree")
def test_readme_python_blocks_run() -> None:
    blocks = re.findall(r"```python\n(.*?)```", README.read_text(), flags=re.S)
    assert len(blocks) >= 2
    namespace: dict[str, object] = {}
    for block in blocks:
        exec(compile(block, str(README), "exec"), namespace)
    world: Any = namespace["world"]
    names = world.schedule.names
    assert names.index("motor_targets") < names.index("wave") < names.index("physics")
    world.close()
    # the Wave system adds exactly its sweep on top of what motor_targets wrote
    plain, waved = World.from_scene("octopus"), World.from_scene("octopus")
    waved.add_system(namespace["Wave"]())  # type: ignore[operator]
    plain.step(2)
    waved.step(2)
    added = waved.motors.target[:, 1] - plain.motors.target[:, 1]
    np.testing.assert_allclose(added, 0.3 * np.sin(2 * np.pi / 60), rtol=1e-9)
    plain.close()
    waved.close()
