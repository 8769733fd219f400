"""The HUD's size: the user's `--ui-scale`, else the display's own factor (its DPI),
1 headless."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pyglet
import pytest
from PIL import Image

from ecs_tentacles.cli import main
from ecs_tentacles.render import gui
from ecs_tentacles.render.gui import display_scale, set_ui_scale
from ecs_tentacles.render.hud import PANEL_SHARE, PANEL_WIDTH


@dataclass
class Display:
    """What a window tells of its display: pyglet's `scale` (DPI / 96), its size and its
    framebuffer's."""

    scale: float
    width: int = 1280
    framebuffer: int = 1280

    def get_framebuffer_size(self) -> tuple[int, int]:
        return self.framebuffer, self.framebuffer * 9 // 16


@pytest.mark.parametrize(
    ("window", "factor"),
    [
        (Display(1.0), 1.0),  # 96 DPI
        (Display(1.5), 1.5),  # 144 DPI, a framebuffer pixel per window pixel (X11, Windows)
        (Display(2.0, framebuffer=2560), 1.0),  # Retina: the framebuffer magnifies already
        (Display(4.5), 3.0),  # at most 3
        (Display(0.25), 0.5),  # at least 0.5
        (object(), 1.0),  # a platform that does not say
    ],
)
def test_the_display_factor_is_its_dpi_over_what_the_framebuffer_enlarges(
    window: Any, factor: float, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setitem(pyglet.options.__dict__, "headless", False)
    assert display_scale(window) == pytest.approx(factor, abs=1e-12)


def test_headless_the_display_factor_is_1() -> None:
    assert pyglet.options["headless"]  # tests/render/conftest.py configures it
    assert display_scale(Display(2.0)) == 1.0


def test_the_users_factor_wins_over_the_displays(
    make_sandbox: Callable[..., Any], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(gui, "display_scale", lambda window: 1.5)  # a 144 DPI display
    sizes = {}
    for factor in (None, 1.0, 2.0):
        set_ui_scale(factor)
        sandbox = make_sandbox("octopus", width=1280, height=720)
        sandbox.render()
        sizes[factor] = (sandbox.hud.gui.scale, sandbox.hud.width)
    wide = PANEL_WIDTH
    assert sizes == {None: (1.5, 1.5 * wide), 1.0: (1.0, wide), 2.0: (2.0, PANEL_SHARE * 1280)}


def _panel_width(shot: Path) -> int:
    """Pixels from the left edge to the HUD panel's right edge: its colour fills most rows
    up to it, inside a one-pixel border."""
    with Image.open(shot) as image:
        pixels = np.asarray(image.convert("RGB")).astype(int)
    colours, counts = np.unique(pixels[:, :40].reshape(-1, 3), axis=0, return_counts=True)
    panel = colours[counts.argmax()]
    share = (np.abs(pixels - panel).max(axis=2) == 0).mean(axis=0)
    return int(np.flatnonzero(share > 0.5)[-1]) + 2


def test_play_scales_the_hud_by_ui_scale_and_by_1_headless_without(tmp_path: Path) -> None:
    argv = ["play", "octopus", "--headless", "--frames", "1", "--quiet"]
    size = ["--width", "1280", "--height", "720"]
    widths = {}
    for factor in (None, "1", "0.8"):
        shot = tmp_path / f"{factor}.png"
        scale = [] if factor is None else ["--ui-scale", factor]
        assert main([*argv, *size, *scale, "--screenshot", str(shot)]) == 0
        widths[factor] = _panel_width(shot)
    assert widths[None] == widths["1"] == pytest.approx(PANEL_WIDTH, abs=2)  # at scale 1
    assert widths["0.8"] == pytest.approx(0.8 * PANEL_WIDTH, abs=2)
