"""The herding game in the sandbox: the HUD's Game section, the banner, mouse and keys.

The section shows the level, creatures penned of those needed, the time left, the
level's best time, the predator's stamina and the level select (`hud_levels`: every
level with its stars; the locked ones greyed). Holding the left button in the view and
dragging points the predator (it follows at its own speed); holding Shift makes it run
(it scares farther and tires); R restarts the level from its start, P pauses, N opens
the next level after a win. When the game ends a banner says how, with the time, the
stars and the best time, and after a win offers the next level; a
win is written to the best-times file once (`ecs_tentacles.herding.best_times`), on
the best-times thread (`win_recorder`): a frame never waits for the file or its lock.

R goes back to the snapshot taken when the level was built; when that no longer fits
the world (a creature removed since, with the director's Delete), the level is built
again from its scene instead (`Sandbox.reset`), and the section says so.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from imgui_bundle import imgui
from pyglet.window import key

from ecs_tentacles.herding import best_times, win_recorder
from ecs_tentacles.herding.game import LOST, WON, HerdingGame
from ecs_tentacles.herding.hud_levels import LevelPicker
from ecs_tentacles.herding.levels import stars_text
from ecs_tentacles.render.registries import Panel
from ecs_tentacles.snapshot import SnapshotMismatch

if TYPE_CHECKING:
    from ecs_tentacles.render.gui import Gui
    from ecs_tentacles.render.registries import SandboxView
    from ecs_tentacles.world import World


class GamePanel(Panel):
    title = "Game"
    order = -20  # first, before the selected creature's Locomotion (-10): the game is the point

    def __init__(self, sandbox: SandboxView):
        self.sandbox = sandbox
        self.win: win_recorder.PendingWin | None = None  # this game's win, once won
        self.writing: list[win_recorder.PendingWin] = []  # wins not written yet (any game)
        self.message = ""
        self.best = self._best()  # read once a game, not every frame
        self.levels = LevelPicker(sandbox)
        win_recorder.start()  # now, not in the frame the game is won

    @property
    def game(self) -> HerdingGame:
        return self.sandbox.world.resource(HerdingGame)

    def attach(self, world: World) -> None:
        self.win, self.message = None, ""
        self.best = self._best()

    def _best(self) -> float | None:
        try:
            return best_times.best_time(self.game.level)
        except OSError:  # an unreadable data folder: no best time shown
            return None

    def _record(self) -> None:
        """Hand a win to the best-times thread once; take in the wins it has written."""
        game = self.game
        if game.outcome == WON and self.win is None:
            self.win = win_recorder.record_later(game.level, game.elapsed)
            self.writing.append(self.win)
        for done in [pending for pending in self.writing if pending.done]:
            self.writing.remove(done)
            if done.best is not None and done.level == game.level:
                self.best = done.best
                self.levels.refresh()  # the next level opens, the stars show
            if done.message:
                self.message = done.message

    def restart(self) -> None:
        """Back to the level's start: its snapshot, or (when a creature was removed since)
        the level built again from its scene."""
        try:
            self.game.restart(self.sandbox.world)
        except SnapshotMismatch:
            if self.sandbox.reset():  # `attach` follows; the Scripts window says a failure
                self.message = "restarted: built again from the scene (a creature was removed)"
            return
        self.attach(self.sandbox.world)

    def next_level(self) -> bool:
        """After a win, open the next level (False: not won, or the last level)."""
        following = self.levels.next(self.game)
        if self.game.outcome != WON or following is None:
            return False
        self.levels.open(following)
        return True

    def draw(self, gui: Gui) -> None:
        if self.levels.open_wanted():
            return  # the section is drawn for the new level from the next frame
        game = self.game
        self.levels.poll_run(game)
        self._record()
        imgui.text(game.level)
        gui.item("game level")
        imgui.text(f"penned {game.penned} of {game.need}")
        gui.item("game penned")
        imgui.text(f"time left {game.left:5.1f} s")
        gui.item("game time")
        best = self.best
        imgui.text(f"best {best:.1f} s" if best is not None else "best: not won yet")
        gui.item("game best")
        self.levels.draw(gui, game)
        imgui.text_wrapped("drag: move the predator  Shift: run  R: restart  P: pause")
        if self.message:
            imgui.text_wrapped(self.message)

    def windows(self, gui: Gui) -> None:
        game = self.game
        self.levels.poll_run(game)
        if game.outcome not in (WON, LOST):
            return
        self._record()
        headline = "You won!" if game.outcome == WON else "Time's up"
        gui.begin_banner("Game over", "game banner", headline, rows=8.5)
        if game.outcome == WON:
            imgui.text(f"{game.penned} penned in {game.elapsed:.1f} s (par {game.par:.0f} s)")
            imgui.text(f"{stars_text(game.stars())}  {game.stars()} of 3 stars")
            imgui.text(self._best_line())
        else:
            imgui.text(f"{game.penned} of {game.need} penned")
        following = self.levels.next(game) if game.outcome == WON else None
        if following is not None:
            if imgui.button(f"Next level: {following.title} (N)"):
                self.next_level()
                imgui.end()
                return
        imgui.text("R: play again")
        imgui.end()

    def _best_line(self) -> str:
        win = self.win
        if win is None or not win.done:
            return "saving the best time..."
        if win.best is None:
            return "best time not saved"
        return "a new best time!" if win.new else f"best time {win.best:.1f} s"

    def key(self, symbol: int, modifiers: int) -> bool:
        if symbol == key.R:
            self.restart()
            return True
        if symbol == key.P:
            self.sandbox.paused = not self.sandbox.paused
            return True
        if symbol == key.N:
            return self.next_level()
        return False

    def press(self, x: float, y: float) -> bool:
        point = self.sandbox.ground_point(x, y)
        if point is None:
            return False
        self.game.aim(self.sandbox.world, (float(point[0]), float(point[1])))
        return True

    def drag(self, x: float, y: float) -> None:
        point = self.sandbox.ground_point(x, y)
        if point is not None:
            self.game.aim(self.sandbox.world, (float(point[0]), float(point[1])))
