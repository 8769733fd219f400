"""The herding game in the sandbox (headless): the Game section, dragging the predator,
R restarting, P pausing, the banner and the best time written once."""

from __future__ import annotations

import json
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from ecs_tentacles.render import configure

configure(headless=True)

from pyglet.window import key, mouse  # noqa: E402  (after configure: pyglet reads it)

from ecs_tentacles.components import Creature  # noqa: E402
from ecs_tentacles.herding.game import HerdingGame  # noqa: E402
from tests.herding.levels import level  # noqa: E402
from tests.herding.lock_holder import lock_held  # noqa: E402
from tests.render.conftest import event, pixel  # noqa: E402


@pytest.fixture
def sandbox(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[Any]:
    from ecs_tentacles.render.sandbox import Sandbox

    monkeypatch.setenv("ECS_TENTACLES_DATA", str(tmp_path / "data"))
    made = Sandbox(level(need=1, seconds=30), headless=True, width=640, height=360)
    try:
        yield made
    finally:
        made.close()


def test_the_game_section_comes_first_and_open(sandbox: Any) -> None:
    sandbox.render()
    rects = sandbox.hud.gui.rects
    assert {"game level", "game penned", "game time", "game best"} <= set(rects)
    assert rects["Game"][1] < rects["Stats"][1]  # above the sandbox's own sections
    assert "game banner" not in sandbox.hud.gui.windows


def test_dragging_in_the_view_aims_the_predator_and_keys_restart_and_pause(sandbox: Any) -> None:
    game = sandbox.world.resource(HerdingGame)
    sandbox.render()
    at = pixel(sandbox, (-0.5, 0.4, 0.0))
    event(sandbox, "on_mouse_press", *at, mouse.LEFT, 0)
    to = pixel(sandbox, (-0.8, -0.3, 0.0))
    event(sandbox, "on_mouse_drag", *to, to[0] - at[0], to[1] - at[1], mouse.LEFT, 0)
    event(sandbox, "on_mouse_release", *to, mouse.LEFT, 0)
    assert len(game.state.log) == 2
    np.testing.assert_allclose(game.state.aim, (-0.8, -0.3), atol=0.03)  # a pixel's width
    sandbox.step(30)
    assert game.state.frames == 30
    event(sandbox, "on_key_press", key.R, 0)  # restart: the level's start
    assert game.state.frames == 0 and sandbox.world.frame == 0 and game.state.log == []
    paused = sandbox.paused
    event(sandbox, "on_key_press", key.P, 0)
    assert sandbox.paused is not paused


def _win(sandbox: Any) -> HerdingGame:
    """Drive creature a into the pen (the predator just behind it) until the game is won."""
    game = sandbox.world.resource(HerdingGame)
    while game.outcome == "playing" and game.elapsed < 30:
        a = sandbox.world.transforms.pos[sandbox.world.creatures.mantle_row[0], :2]
        game.aim(sandbox.world, (float(a[0]) - 0.7, float(a[1])))
        sandbox.step(15)
    assert game.outcome == "won"
    return game


def test_a_win_shows_the_banner_and_writes_the_best_time_once(sandbox: Any, tmp_path: Path) -> None:
    game = _win(sandbox)
    sandbox.render()
    assert sandbox.panel("Game").win.wait(10)
    sandbox.render()
    assert "game banner" in sandbox.hud.gui.windows
    saved = json.loads((tmp_path / "data" / "best_times.json").read_text())
    assert saved["best_seconds"] == {"test level": game.elapsed}  # as it is, not rounded
    assert sandbox.panel("Game").best == game.elapsed
    mtime = (tmp_path / "data" / "best_times.json").stat().st_mtime_ns
    sandbox.render()
    assert (tmp_path / "data" / "best_times.json").stat().st_mtime_ns == mtime  # once


def test_a_win_while_another_game_holds_the_file_never_holds_up_a_frame(
    sandbox: Any, tmp_path: Path
) -> None:
    file = tmp_path / "data" / "best_times.json"
    game = _win(sandbox)
    panel = sandbox.panel("Game")
    with lock_held(tmp_path / "data") as holder:
        started = time.perf_counter()
        sandbox.render()  # the frame the win is seen in (it was written from here)
        sandbox.render()
        took = time.perf_counter() - started
        assert took < 2.0, f"two frames took {took:.1f} s"  # the lock: 30 s
        assert "game banner" in sandbox.hud.gui.windows
        assert not panel.win.done and not file.exists()  # the lock is still held
        holder.release()
        assert panel.win.wait(10)
    sandbox.render()
    assert json.loads(file.read_text())["best_seconds"] == {"test level": game.elapsed}
    assert panel.best == game.elapsed and panel.message == ""


def test_r_after_a_creature_is_deleted_restarts_the_level(sandbox: Any) -> None:
    world = sandbox.world
    game = world.resource(HerdingGame)
    sandbox.step(20)
    sandbox.select(world.creature("a"))
    event(sandbox, "on_key_press", key.DELETE, 0)  # the director's Delete
    assert sorted(c.name for _, c in world.query(Creature)) == ["b"]
    event(sandbox, "on_key_press", key.R, 0)  # the start's snapshot names a: built again
    world = sandbox.world
    game = world.resource(HerdingGame)
    assert sorted(c.name for _, c in world.query(Creature)) == ["a", "b"]
    assert world.frame == 0 and game.state.frames == 0 and game.state.log == []
    assert "restarted" in sandbox.panel("Game").message
    sandbox.render()
    sandbox.step(10)
    event(sandbox, "on_key_press", key.R, 0)  # and R goes on restarting from the snapshot
    assert sandbox.world is world and world.frame == 0 and game.state.frames == 0


def test_the_section_shows_stamina_and_the_level_select(sandbox: Any) -> None:
    sandbox.render()
    assert {"game stamina", "game levels"} <= set(sandbox.hud.gui.rects)
    game = sandbox.world.resource(HerdingGame)
    sandbox.keys.on_key_press(key.LSHIFT, 0)  # held: the predator runs
    sandbox.render()
    assert game.state.running and game.state.runs == [(0, True)]
    sandbox.keys.on_key_release(key.LSHIFT, 0)
    sandbox.render()
    assert not game.state.running


def test_a_win_offers_the_next_level_and_n_opens_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Level 1's rules on the small test level: won, the banner offers level 2 and N
    opens it (the level select then lists level 2 open)."""
    from ecs_tentacles.render.sandbox import Sandbox

    monkeypatch.setenv("ECS_TENTACLES_DATA", str(tmp_path / "data"))
    made = Sandbox(level(need=1, level="1. Open field"), headless=True, width=640, height=360)
    try:
        _win(made)
        made.render()
        panel = made.panel("Game")
        assert panel.win.wait(10)
        made.render()
        assert "game banner" in made.hud.gui.windows
        assert panel.levels.next(made.world.resource(HerdingGame)).scene == "herding_2_shore"
        event(made, "on_key_press", key.N, 0)
        game = made.world.resource(HerdingGame)
        assert game.level == "2. Rocky shore" and made.world.creatures.count == 48
        assert [lv.unlocked for lv in made.panel("Game").levels.levels][:3] == [True, True, False]
    finally:
        made.close()
