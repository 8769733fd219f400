"""The systems page's example does what the page says: `Wave` runs between motor_targets
and physics and adds exactly its sweep (docs/extending/systems.md)."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from ecs_tentacles.world import World

PAGE = Path(__file__).resolve().parents[2] / "docs" / "extending" / "systems.md"


@pytest.mark.skipif(not PAGE.exists(), reason="needs the source tree")
def test_the_wave_system_sits_and_sweeps_as_the_page_says() -> None:
    blocks = re.findall(r"```python\n(.*?)```", PAGE.read_text(), flags=re.S)
    assert len(blocks) == 1
    namespace: dict[str, object] = {}
    for block in blocks:
        exec(compile(block, str(PAGE), "exec"), namespace)
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
