"""What every game mode's HUD section shares: R restarts the level, P pauses.

A mode's panel (`herding.hud.GamePanel`, `race.hud.RacePanel`) subclasses `ModePanel`
and names its game resource (`played`). Reads: the sandbox's world (that resource) and
its pause flag. Writes: the world back at the level's start, the pause flag, `message`
(what the section says after a restart that had to build the level again).
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import TYPE_CHECKING

from pyglet.window import key

from ecs_tentacles.render.registries import Panel
from ecs_tentacles.snapshot import SnapshotMismatch

if TYPE_CHECKING:
    from ecs_tentacles.game.modes import PlayedGame
    from ecs_tentacles.render.registries import SandboxView


class ModePanel(Panel, ABC):
    """A game mode's HUD section: `restart` (R) and pause (P); subclasses draw the rest."""

    order = -20  # first, before the selected creature's Locomotion (-10): the game is the point

    def __init__(self, sandbox: SandboxView):
        self.sandbox = sandbox
        self.message = ""

    @property
    @abstractmethod
    def played(self) -> PlayedGame:
        """The mode's game resource in the sandbox's world."""

    def restart(self) -> bool:
        """Back to the level's start: its snapshot (True), or (when a creature was removed
        since) the level built again from its scene (False; `attach` follows a rebuild)."""
        try:
            self.played.restart(self.sandbox.world)
        except SnapshotMismatch:
            if self.sandbox.reset():  # the Scripts window says a failure
                self.message = "restarted: built again from the scene (a creature was removed)"
            return False
        return True

    def key(self, symbol: int, modifiers: int) -> bool:
        if symbol == key.R:
            self.restart()
            return True
        if symbol == key.P:
            self.sandbox.paused = not self.sandbox.paused
            return True
        return False
