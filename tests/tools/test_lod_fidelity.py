"""tools/lod_fidelity.py: the overlap probe sees two creatures pushed into each other, and a
short comparison reports what its doc promises."""

from __future__ import annotations

import numpy as np
import pytest

from ecs_tentacles.components import Transform
from ecs_tentacles.world import World
from tests.tools.loader import TOOLS, load_tool

TOOL = TOOLS / "lod_fidelity.py"


@pytest.mark.skipif(not TOOL.is_file(), reason="needs the source tree")
def test_the_overlap_probe_measures_capsules_pushed_into_each_other() -> None:
    tool = load_tool("lod_fidelity")
    octo = {"tentacles": {"count": 4, "links": 3}}
    scene = {
        "version": 1,
        "creatures": [{**octo, "name": "a"}, {**octo, "name": "b", "position": [3, 0]}],
    }
    with World.from_scene(scene) as world:
        rows, half, radius = tool._capsules(world)
        assert tool.deepest_overlap(world, rows, half, radius) == 0.0  # 3 m apart
        b = world.creature("b")
        moved = world.transforms.pos[rows[1]] - [3.0 - 0.02, 0.0, 0.0]  # b's links onto a's
        world.transforms.pos[rows[1]] = moved
        world.transforms.pos[world.component(b, Transform).row, 0] -= 2.98
        assert tool.deepest_overlap(world, rows, half, radius) > 0.01


@pytest.mark.skipif(not TOOL.is_file(), reason="needs the source tree")
def test_a_short_comparison_reports_progress_goals_overlap_and_recoveries() -> None:
    tool = load_tool("lod_fidelity")
    on, off = (tool.run(4, 0.2, lod, 5, 0) for lod in (True, False))
    result = tool.compare(on, off)
    assert set(on["progress"]) == set(off["progress"]) and len(on["progress"]) == 4
    assert np.isfinite(result["progress_ratio"])
    assert result["recoveries"] == {"lod": 0, "off": 0}
    assert result["deepest_mm"]["lod"] >= 0.0 and result["reached"]["both"] >= 0
