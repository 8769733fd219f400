"""Level of detail in the sandbox: what the camera and the selection promote, the HUD's
tier counts and its "show tiers" markers, and `play --lod/--focus`."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from ecs_tentacles.cli import main
from ecs_tentacles.render.session import CLOSE_UP, FOCUS_RADIUS
from ecs_tentacles.render.tiers import COLOURS, tier_markers
from tests.cli.test_measure import lod_crowd
from tests.render.conftest import click_item


def test_the_camera_target_and_the_selection_run_full(make_sandbox: Callable[..., Any]) -> None:
    sandbox = make_sandbox(
        lod_crowd(focus=False)
    )  # 6 creatures 4 m apart; budgets 1 full + 2 reduced
    assert sandbox.camera_focus
    sandbox.select(None)
    creatures = sandbox.renderer.creature_entities
    mantles = sandbox.world.transforms.pos[sandbox.renderer.mantle_rows]
    camera = sandbox.renderer.camera
    camera.target, camera.distance = np.array([*mantles[0, :2], 0.0]), 4.0  # close, on the first
    sandbox.step(2)
    lod = sandbox.world.lod
    distance = np.linalg.norm(mantles[:, :2] - mantles[0, :2], axis=1)
    near = distance <= FOCUS_RADIUS
    assert near.sum() == 1  # the one looked at
    assert lod.tier_of(creatures[0]) == "full"
    assert lod.counts()["full"] == 1  # the budget of 1 counts it: none besides
    camera.distance = CLOSE_UP + 1.0  # backed off: too small on screen for full physics
    sandbox.step(2)
    assert lod.tier_of(creatures[0]) == "reduced" and lod.counts()["full"] == 0
    camera.distance = CLOSE_UP
    sandbox.step(2)
    assert lod.tier_of(creatures[0]) == "full"
    sandbox.renderer.camera.target = np.array([*(mantles[0, :2] + [FOCUS_RADIUS + 0.5, 0.0]), 0])
    sandbox.step(2)  # nobody inside the focus: nobody full, the nearest reduced
    nearest = creatures[int(np.argmin(np.linalg.norm(
        mantles[:, :2] - sandbox.renderer.camera.target[:2], axis=1)))]  # fmt: skip
    assert lod.tier_of(nearest) == "reduced"
    assert lod.counts() == {"full": 0, "reduced": 2, "kinematic": 4}
    sandbox.renderer.camera.target = np.array([100.0, 100.0, 0.0])  # look far away
    selected = creatures[-1]
    sandbox.select(selected)
    sandbox.step(2)
    assert lod.tier_of(selected) == "full"  # the selection uses the budget of 1
    assert lod.counts() == {"full": 1, "reduced": 2, "kinematic": 3}


def test_a_pinned_focus_ignores_the_camera(make_sandbox: Callable[..., Any]) -> None:
    sandbox = make_sandbox(lod_crowd(), focus=(100.0, 100.0, 1.0))
    assert not sandbox.camera_focus
    sandbox.select(None)
    sandbox.step(2)
    assert sandbox.world.lod.counts() == {"full": 1, "reduced": 2, "kinematic": 3}
    sandbox.reset()  # a rebuilt world keeps the pinned focus
    sandbox.select(None)
    sandbox.step(2)
    assert sandbox.world.lod.counts() == {"full": 1, "reduced": 2, "kinematic": 3}
    off = make_sandbox(lod_crowd(), lod=False, focus=(100.0, 100.0, 1.0))
    off.step(2)
    assert off.world.lod.counts()["full"] == 6


def test_hud_counts_tiers_and_its_box_shows_a_marker_per_creature(
    make_sandbox: Callable[..., Any],
) -> None:
    sandbox = make_sandbox(lod_crowd(), focus=(100.0, 100.0, 1.0))
    sandbox.select(None)
    sandbox.step(2)
    sandbox.hud.unfold("Physics")
    sandbox.render()
    rects = sandbox.hud.gui.rects
    assert {"tier full", "tier reduced", "tier kinematic", "promotions", "show tiers"} <= set(rects)
    assert rects["tier full"][1] == rects["tier kinematic"][1]  # one row: the legend
    spheres = sandbox.renderer.spheres.count
    click_item(sandbox, "show tiers", 0.1)
    assert sandbox.hud.show_tiers and sandbox.renderer.show_tiers
    assert sandbox.renderer.spheres.count == spheres + 6
    markers = tier_markers(sandbox.renderer)
    assert [(len(m.positions), m.rgba) for m in markers] == [
        (1, COLOURS["full"]),
        (2, COLOURS["reduced"]),
        (3, COLOURS["kinematic"]),
    ]
    mantles = sandbox.world.transforms.pos[sandbox.renderer.mantle_rows]
    above = np.vstack([m.positions for m in markers])
    assert (above[:, 2] > mantles[:, 2].max()).all()  # over the mantles, not inside
    before = sandbox.renderer.target.read().copy()
    click_item(sandbox, "show tiers", 0.1)
    assert not sandbox.renderer.show_tiers
    assert sandbox.renderer.spheres.count == spheres
    assert not np.array_equal(before, sandbox.renderer.target.read())


def test_play_lod_and_focus_options(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    scene = tmp_path / "crowd.json"
    scene.write_text(json.dumps(lod_crowd()))
    argv = ["play", str(scene), "--headless", "--frames", "2", "--quiet", "--json"]
    argv += ["--width", "320", "--height", "180"]
    assert main([*argv, "--focus=100,100,1"]) == 0
    tiers = json.loads(capsys.readouterr().out)["tiers"]
    assert tiers == {"full": 1, "reduced": 2, "kinematic": 3}  # the selected one fills the 1
    assert main([*argv, "--focus=100,100,1", "--lod", "off"]) == 0
    assert json.loads(capsys.readouterr().out)["tiers"]["full"] == 6
