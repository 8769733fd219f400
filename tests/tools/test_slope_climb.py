"""tools/slope_climb.py on short runs: the octopus starts on the flat before a ramp of the
asked slope, the CSV has a row per slope, and the plot is a real PNG."""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from ecs_tentacles.ground import ground_of
from ecs_tentacles.world import World
from tests.tools.loader import TOOLS, load_tool

pytestmark = pytest.mark.skipif(not TOOLS.is_dir(), reason="needs the source tree")


def test_the_ramp_rises_at_the_slope_past_the_foot() -> None:
    slope = load_tool("slope_climb")
    scene = slope.ramp_scene(20.0)
    world = World.from_scene(scene)
    try:
        ground = ground_of(world)
        foot = scene["creatures"][0]["position"][0] + slope.START
        heights = ground.height(np.array([[foot - 0.5, 0.0], [foot + 1.0, 0.0], [foot + 2.0, 0.0]]))
        rise = math.tan(math.radians(20.0))
        assert heights.tolist() == pytest.approx([0.0, rise, 2 * rise], abs=1e-4)
        goal = scene["creatures"][0]["goals"][0]["position"]
        assert goal[0] - foot == pytest.approx(slope.UP * math.cos(math.radians(20.0)), abs=1e-3)
    finally:
        world.close()


def test_short_runs_write_the_csv_and_the_plot(tmp_path: Path) -> None:
    slope = load_tool("slope_climb")
    argv = ["--slopes", "0,30", "--seconds", "2", "--jobs", "1", "--out", str(tmp_path / "s")]
    assert slope.main(argv) == 0
    with open(tmp_path / "s.csv", newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert [r["slope_deg"] for r in rows] == ["0.0", "30.0"]
    assert all(r["reached"] == "False" and r["recoveries"] == "0" for r in rows)
    with Image.open(tmp_path / "s.png") as image:
        assert image.size[0] > 400
