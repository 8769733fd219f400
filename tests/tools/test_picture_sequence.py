"""tools/picture_sequence.py: the four moments land in reading order, the GIF keeps every frame."""

from __future__ import annotations

from pathlib import Path

import pytest
from PIL import Image, ImageSequence

from tests.tools.loader import TOOLS, load_tool

pytestmark = pytest.mark.skipif(not TOOLS.is_dir(), reason="needs the source tree")
COLOURS = [(255, 0, 0), (0, 255, 0), (0, 0, 255), (255, 255, 0)]


def test_the_sheet_reads_left_to_right_then_down_and_the_gif_loops_every_frame(
    tmp_path: Path,
) -> None:
    tool = load_tool("picture_sequence")
    moments = [Image.new("RGB", (80, 45), c) for c in COLOURS]
    png, gif = tool.save_sequence(tmp_path, "demo", moments, moments * 2, 40, 120)
    assert (png.name, gif.name) == ("demo_sequence.png", "demo.gif")
    sheet = Image.open(png).convert("RGB")
    assert sheet.size == (160, 90)
    centres = [(40, 22), (120, 22), (40, 67), (120, 67)]
    assert [sheet.getpixel(p) for p in centres] == COLOURS
    animation = Image.open(gif)
    frames = sum(1 for _ in ImageSequence.Iterator(animation))
    assert (animation.size, frames) == ((40, 22), 8)
    assert animation.info["duration"] == 120 and animation.info["loop"] == 0


def test_a_sheet_needs_four_moments(tmp_path: Path) -> None:
    tool = load_tool("picture_sequence")
    with pytest.raises(ValueError, match="moments: a sheet holds 4 pictures, got 3"):
        tool.save_sequence(tmp_path, "demo", [Image.new("RGB", (8, 8))] * 3, [], 8, 100)
    assert not list(tmp_path.iterdir())  # nothing written
