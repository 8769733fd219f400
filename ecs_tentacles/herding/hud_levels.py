"""The Game section's level select and "next level", and the predator's run in the HUD.

    picker = LevelPicker(sandbox)
    picker.draw(gui, game)         # the stamina bar, and a combo of levels (stars, locked)
    picker.open(level)             # play another level (the sandbox rebuilds its world)
    picker.next(game)              # the level after this one, None after the last

The combo lists `ecs_tentacles.herding.levels.levels()`, read when the section is
made and after each win (never every frame); a locked level is shown but cannot be
picked. Opening a level builds the world again from that bundled scene
(`SandboxView.rebuild`); the camera stays. Shift held (in the view or not) makes the
predator run (`HerdingGame.run`), so the HUD polls it each frame it draws.

Reads: the levels and best times, the sandbox's keys. Writes: the sandbox's world (a
level opened), `HerdingGame.run`.
"""

from __future__ import annotations

import json
from typing import TYPE_CHECKING

from imgui_bundle import imgui
from pyglet.window import key

from ecs_tentacles.herding.levels import Level, levels, stars_text
from ecs_tentacles.scene.load import bundled_scene

if TYPE_CHECKING:
    from ecs_tentacles.herding.game import HerdingGame
    from ecs_tentacles.render.gui import Gui
    from ecs_tentacles.render.registries import SandboxView


class LevelPicker:
    """The level select, the next level, and Shift to run."""

    def __init__(self, sandbox: SandboxView):
        self.sandbox = sandbox
        self.levels: list[Level] = []
        self.wanted: Level | None = None  # picked in the combo: opened before the next draw
        self.refresh()

    def refresh(self) -> None:
        """Read the levels again (after a win: the next one opens)."""
        try:
            self.levels = levels()
        except OSError:
            self.levels = []

    def current(self, game: HerdingGame) -> Level | None:
        return next((level for level in self.levels if level.title == game.level), None)

    def next(self, game: HerdingGame) -> Level | None:
        """The level after this one in its mode (a win opens it), None after the last."""
        here = self.current(game)
        if here is None:
            return None
        after = self.levels[self.levels.index(here) + 1 :]
        return next((level for level in after if level.mode == here.mode), None)

    def open(self, level: Level) -> None:
        """Play `level`: the world built again from its bundled scene."""
        scene = json.loads(bundled_scene(level.scene).read_text(encoding="utf-8"))
        self.sandbox.select_many([])  # (a rebuild keeps the selection by name: not there)
        self.sandbox.rebuild(scene)

    def open_wanted(self) -> bool:
        """Open the level picked in the combo, if any (True: the world changed)."""
        level, self.wanted = self.wanted, None
        if level is None:
            return False
        self.open(level)
        return True

    def poll_run(self, game: HerdingGame) -> None:
        """The predator runs while Shift is held."""
        keys = self.sandbox.keys
        held = bool(keys is not None and (keys[key.LSHIFT] or keys[key.RSHIFT]))
        if held != game.state.running:
            game.run(self.sandbox.world, held)

    def draw(self, gui: Gui, game: HerdingGame) -> None:
        state = game.state
        label = "winded" if state.winded else "running" if game.sprinting else "walking"
        imgui.progress_bar(state.stamina, (-1.0, 0.0), f"stamina: {label}")
        gui.item("game stamina")
        here = self.current(game)
        preview = f"{stars_text(here.stars)} {here.title}" if here else game.level
        if imgui.begin_combo("level", preview):
            for level in self.levels:
                name = f"{stars_text(level.stars)} {level.title}"
                if not level.unlocked:
                    imgui.text_disabled(f"{name} (locked)")
                elif imgui.selectable(name, level is here)[0] and level is not here:
                    self.wanted = level  # not mid-draw: the world would change under it
            imgui.end_combo()
        gui.item("game levels")
        if here is not None:
            imgui.text(f"par {here.par:.0f} s: 3 stars; {1.5 * here.par:.0f} s: 2")
            gui.item("game par")
