"""The sandbox and user code: a failing system is disabled and shown; a changed file reloads.

Driven headless (EGL): the sandbox keeps stepping, the Scripts window shows the
failure in red with a re-enable button, and a fixed file is swapped in.
"""

from __future__ import annotations

import json
import logging
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from ecs_tentacles.locomotion.goals import GoalBook
from tests.render.conftest import click_item

WAVE = '''
from ecs_tentacles.system import System


class Wave(System):
    """Reads the frame; writes world.waved (frames it ran); {what}."""

    name = "wave"
    stage = "act"

    def setup(self, world):
        world.waved = getattr(world, "waved", [])

    def process(self, world, dt):
        world.waved.append(world.frame)
        {body}
'''
BROKEN = WAVE.format(what="fails from frame 5 on", body="if world.frame >= 5: {}['amplitude']")
FIXED = WAVE.format(what="never fails", body="pass")


@pytest.fixture
def scene(tmp_path: Path) -> Path:
    (tmp_path / "mywave.py").write_text(BROKEN)
    data = {
        "version": 1,
        "plugins": {"mywave": {"from": "mywave.py"}},
        "creatures": [
            {"name": "octo", "tentacles": {"count": 6, "links": 4}, "goals": [{"position": [1, 0]}]}
        ],
    }
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(data))
    return path


def _red_text(sandbox: Any, rect: tuple[float, float, float, float]) -> int:
    """Pixels in GUI rectangle `rect` that are the failure red."""
    pixels = sandbox.renderer.target.read().astype(int)
    x0, y0, x1, y1 = (round(v) for v in rect)
    box = pixels[y0:y1, x0:x1]
    return int(((box[..., 0] > 150) & (box[..., 1] < 90) & (box[..., 2] < 90)).sum())


def test_a_failing_system_is_disabled_shown_and_can_run_again(
    scene: Path,
    make_sandbox: Callable[..., Any],
    caplog: pytest.LogCaptureFixture,
    tmp_path: Path,
) -> None:
    sandbox = make_sandbox(scene, allow_systems=True, width=960, height=540)
    octo = sandbox.world.creature("octo")
    with caplog.at_level(logging.ERROR, logger="ecs_tentacles.scripting"):
        sandbox.run_headless(20, progress=False)  # no exception: the sandbox goes on
    world = sandbox.world
    assert world.frame == 20 and world.waved == [0, 1, 2, 3, 4, 5]
    assert world.schedule.disabled() == ["wave"]
    assert world.creature("octo") == octo and world.resource(GoalBook).path(octo)  # still crawling
    [record] = caplog.records
    assert record.getMessage().startswith(
        "system 'wave' (plugin 'mywave') failed at frame 5: KeyError: 'amplitude'; system disabled"
        "\nTraceback (most recent call last):\n"
        f'  File "{tmp_path / "mywave.py"}", line 16, in process'
    )
    [failure] = sandbox.scripts.failures
    assert failure.headline == "wave (plugin mywave) failed at frame 5, disabled"
    assert failure.error == "KeyError: 'amplitude'"
    sandbox.screenshot(tmp_path / "failure.png")  # to look at: pytest --basetemp=DIR
    gui = sandbox.hud.gui
    x0, y0, x1, _ = gui.windows["scripts"]
    assert x1 == pytest.approx(960 - 8, abs=1) and y0 == pytest.approx(8, abs=1)
    assert x0 > sandbox.hud.width  # beside the HUD panel, over the 3D view
    assert _red_text(sandbox, gui.rects["failure wave"]) > 50
    assert _red_text(sandbox, gui.rects["error wave"]) > 30
    click_item(sandbox, "enable wave")  # the button: it runs again, and fails again
    assert world.schedule.disabled() == [] and sandbox.scripts.failures == []
    sandbox.step(1)
    assert world.waved[-1] == 20 and world.schedule.disabled() == ["wave"]
    assert sandbox.scripts.failures[0].frame == 20


def test_a_fixed_file_is_reloaded_and_runs_again(
    scene: Path, make_sandbox: Callable[..., Any], tmp_path: Path
) -> None:
    sandbox = make_sandbox(scene, allow_systems=True, width=960, height=540)
    sandbox.step(8)
    world = sandbox.world
    pos = world.transforms.pos.copy()
    (tmp_path / "mywave.py").write_text(FIXED)
    os.utime(tmp_path / "mywave.py", ns=(0, 10**18))
    assert sandbox.scripts.poll(0.0) == []  # not yet: the reloader looks twice a second
    [done] = sandbox.scripts.poll(1e9)
    assert done.message == "reloaded mywave.py (wave)"
    assert sandbox.scripts.failures == [] and world.schedule.disabled() == []
    assert np.array_equal(world.transforms.pos, pos) and world.frame == 8
    sandbox.step(3)
    assert world.waved == [0, 1, 2, 3, 4, 5, 8, 9, 10]  # the new code, from frame 8 on
    sandbox.render()
    sandbox.render()
    sandbox.screenshot(tmp_path / "reloaded.png")
    assert "note 0" in sandbox.hud.gui.rects
    pixels = sandbox.renderer.target.read().astype(int)
    x0, y0, x1, y1 = (round(v) for v in sandbox.hud.gui.rects["note 0"])
    box = pixels[y0:y1, x0:x1]
    assert ((box[..., 1] > box[..., 0] + 40) & (box[..., 1] > box[..., 2] + 20)).sum() > 30  # green


def test_reset_with_broken_code_keeps_the_world_and_says_why(
    scene: Path, make_sandbox: Callable[..., Any], tmp_path: Path
) -> None:
    sandbox = make_sandbox(scene, allow_systems=True)
    sandbox.step(8)
    world = sandbox.world
    (tmp_path / "mywave.py").write_text("class Wave(:\n")
    assert sandbox.reset() is False
    assert sandbox.world is world and world.frame == 8  # still there, still running
    sandbox.step(1)
    ok, line = sandbox.scripts.notes[-1]
    assert not ok and line.startswith(
        f"not reset: {scene}: plugins.mywave: cannot import 'mywave.py': SyntaxError:"
    )
    (tmp_path / "mywave.py").write_text(FIXED)
    assert sandbox.reset() is True
    assert sandbox.world is not world and sandbox.world.frame == 0
    assert sandbox.scripts.failures == [] and sandbox.scripts.reloader is not None
    assert sandbox.scripts.reloader.world is sandbox.world


def _inside(rect: tuple[float, ...], region: tuple[float, ...]) -> bool:
    return (
        region[0] <= rect[0]
        and rect[2] <= region[2]
        and region[1] <= rect[1]
        and rect[3] <= region[3]
    )


@pytest.mark.parametrize(
    ("scale", "size"),
    [(0.5, (1280, 720)), (1.0, (1280, 720)), (2.0, (1280, 720)), (3.0, (1280, 720)),
     (1.0, (640, 360)), (3.0, (640, 360))],
)  # fmt: skip
def test_the_scripts_window_never_clips_its_buttons(
    scene: Path, make_sandbox: Callable[..., Any], scale: float, size: tuple[int, int]
) -> None:
    """The "clear" and "re-enable" buttons lie whole inside the window's visible content,
    on the very frame a line is added (a screenshot taken then), at every UI scale."""
    from ecs_tentacles.render.gui import set_ui_scale

    set_ui_scale(scale)  # (tests/render/conftest.py sets it back)
    sandbox = make_sandbox(scene, allow_systems=True, width=size[0], height=size[1])
    sandbox.render()  # nothing to say yet: no Scripts window
    assert "scripts" not in sandbox.hud.gui.windows
    sandbox.step(6)  # the wave fails at frame 5
    sandbox.scripts.say(True, "saved octopus_directed.json")
    lines = ["not reset: creatures[0].tentacles.links: must be >= 2, got 0", "reloaded mywave.py"]
    for line in ["", *lines]:
        if line:
            sandbox.scripts.say(False, line)  # the window grows on this frame
        sandbox.render()
        gui = sandbox.hud.gui
        window, visible = gui.windows["scripts"], gui.clips["scripts"]
        assert _inside(window, (0, 0, *size))
        for name in ("clear notes", "enable wave"):
            assert _inside(gui.rects[name], visible), (name, gui.rects[name], visible)
    click_item(sandbox, "clear notes")
    assert not sandbox.scripts.notes
