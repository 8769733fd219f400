"""The clean view (a game, `play --clean`, a video): none of the editor's overlays are
drawn (selection rings and names, goal rings and paths, sucker dots, tier spheres, the
fur timeline, the metre grid), while a game's own drawing and HUD stay (pixels read
back, and the renderer's draw lists)."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from PIL import Image

from ecs_tentacles.cli import main
from ecs_tentacles.locomotion.goals import GoalBook
from ecs_tentacles.render.camera import CameraChoice
from ecs_tentacles.render.registries import Lines, OverlayLines, OverlaySpheres, Spheres

SCENE = {
    "version": 1,
    "creatures": [
        {"name": "octo", "position": [0, 0], "goals": [{"position": [1.5, 1.0]}]},
    ],
}


def _picture(sandbox: Any) -> np.ndarray:
    sandbox.render()  # twice: a HUD window is laid out on its first frame
    sandbox.render()
    return np.asarray(sandbox.renderer.target.read()[..., :3], dtype=np.int16)


def test_the_clean_view_draws_no_selection_goal_or_grid(make_sandbox: Callable[..., Any]) -> None:
    sandbox = make_sandbox(SCENE, hud=False)
    assert sandbox.clean is False  # not a game: the editor's view
    sandbox.aim(CameraChoice("fixed", eye=(-2.0, -3.0, 2.5), target=(0.6, 0.4, 0.0)))
    assert sandbox.renderer.selected is not None  # the first creature, selected
    editor = _picture(sandbox)
    sandbox.clean = True
    clean = _picture(sandbox)
    # the selection ring, the goal's ring and path and the grid were drawn, and are not
    assert (np.abs(editor - clean).max(axis=2) > 30).sum() > 300
    # in the clean view, taking the selection and the goal away changes no pixel
    sandbox.select(None)
    sandbox.world.resource(GoalBook).clear(sandbox.world.creature("octo"))
    np.testing.assert_array_equal(_picture(sandbox), clean)
    sandbox.clean = False
    grid = np.abs(_picture(sandbox) - clean).max(axis=2)
    assert (grid > 6).sum() > 1000 and grid.max() < 30  # the grid's faint lines, only


def test_a_game_starts_clean_and_keeps_its_own_drawing_and_hud(
    make_sandbox: Callable[..., Any],
) -> None:
    sandbox = make_sandbox("herding_1_field")
    assert sandbox.clean is True  # a scene with a `game` key
    sandbox.step(30)
    world, renderer = sandbox.world, sandbox.renderer
    game = sum(
        len(v) for entry in world.registry(Lines) for v in entry(world, renderer.render_view)
    )
    clean = _picture(sandbox)
    lines = renderer._line_vertices(world.transforms.pos)
    assert 0 < len(lines) == game  # the game's pen and reach rings, nothing of the editor's
    spheres = sum(len(m.positions) for entry in world.registry(Spheres) for m in entry(world))
    assert len(renderer._sphere_instances()) == spheres  # the predator, no sucker dots
    assert len(world.registry(OverlayLines)) and len(world.registry(OverlaySpheres))
    sandbox.clean = False  # o
    editor = _picture(sandbox)
    assert len(renderer._line_vertices(world.transforms.pos)) > game  # the selection ring
    height = clean.shape[0]
    panel = (slice(24, height // 3), slice(0, 100))  # the game section (under the title bar)
    np.testing.assert_array_equal(clean[panel], editor[panel])
    timeline = (slice(height - 40, height), slice(sandbox.hud.width + 10, None))
    assert np.abs(editor[timeline] - clean[timeline]).mean() > 10  # the fur timeline


@pytest.mark.parametrize("flag", ["--clean", "--no-clean"])
def test_play_takes_clean_and_no_clean(tmp_path: Path, flag: str) -> None:
    argv = ["play", "three_goals", "--headless", "--frames", "2", "--quiet", "--no-hud"]
    argv += ["--width", "320", "--height", "180"]
    default, chosen = tmp_path / "default.png", tmp_path / "chosen.png"
    assert main([*argv, "--screenshot", str(default)]) == 0
    assert main([*argv, "--screenshot", str(chosen), flag]) == 0
    with Image.open(default) as a, Image.open(chosen) as b:
        same = np.array_equal(np.asarray(a), np.asarray(b))
    assert same == (flag == "--no-clean")  # a screenshot of a scene keeps the editor's view


def test_play_refuses_clean_with_no_clean(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exit_:
        main(["play", "octopus", "--headless", "--json", "--clean", "--no-clean"])
    assert exit_.value.code == 2
    assert "--no-clean: not allowed with argument --clean" in capsys.readouterr().err
