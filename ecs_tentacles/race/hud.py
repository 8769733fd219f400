"""The race in the sandbox: the HUD's Race section, the banner, mouse and keys.

The section shows the level, the time left and how to steer. A left click in the view
sends the runner there (its path is that point); shift+click adds a point to its path.
R restarts the level from its start, P pauses. When the race ends a banner says who
took the flag.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from imgui_bundle import imgui
from pyglet.window import key

from ecs_tentacles.game.modes import LOST, WON
from ecs_tentacles.race.game import RaceGame
from ecs_tentacles.render.registries import Panel
from ecs_tentacles.snapshot import SnapshotMismatch

if TYPE_CHECKING:
    from ecs_tentacles.render.gui import Gui
    from ecs_tentacles.render.registries import SandboxView
    from ecs_tentacles.world import World


class RacePanel(Panel):
    title = "Race"
    order = -20  # first: the game is the point

    def __init__(self, sandbox: SandboxView):
        self.sandbox = sandbox
        self.message = ""

    @property
    def race(self) -> RaceGame:
        return self.sandbox.world.resource(RaceGame)

    def attach(self, world: World) -> None:
        self.message = ""

    def restart(self) -> None:
        """Back to the level's start (built again from its scene if a creature was removed)."""
        try:
            self.race.restart(self.sandbox.world)
        except SnapshotMismatch:
            if self.sandbox.reset():
                self.message = "restarted: built again from the scene (a creature was removed)"

    def draw(self, gui: Gui) -> None:
        race = self.race
        imgui.text(race.level)
        gui.item("race level")
        imgui.text(f"time left {race.left:5.1f} s")
        gui.item("race time")
        imgui.text(f"you: {race.runner_name} (gold ring)")
        imgui.text_wrapped("click: go there  shift+click: and then there  R: restart  P: pause")
        if self.message:
            imgui.text_wrapped(self.message)

    def windows(self, gui: Gui) -> None:
        race = self.race
        if race.outcome not in (WON, LOST):
            return
        headline = "You won!" if race.outcome == WON else "You lost"
        gui.begin_banner("Race over", "race banner", headline, rows=5.5)
        winner = race.winner_name(self.sandbox.world)
        if race.outcome == WON:
            imgui.text(f"flag taken in {race.elapsed:.1f} s")
        else:
            imgui.text(f"{winner} took the flag" if winner else "the time ran out")
        imgui.text("R: race again")
        imgui.end()

    def key(self, symbol: int, modifiers: int) -> bool:
        if symbol == key.R:
            self.restart()
            return True
        if symbol == key.P:
            self.sandbox.paused = not self.sandbox.paused
            return True
        return False

    def press(self, x: float, y: float) -> bool:
        point = self.sandbox.ground_point(x, y)
        if point is None:
            return False
        add = bool(self.sandbox.modifiers & key.MOD_SHIFT)
        self.race.steer(self.sandbox.world, (float(point[0]), float(point[1])), add=add)
        return True
