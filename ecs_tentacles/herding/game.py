"""`HerdingGame`: the herding game's state, a world resource (`world.resource(HerdingGame)`).

    game = world.resource(HerdingGame)
    game.aim(world, (1.0, 2.0))     # the player points the predator there (logged)
    game.penned, game.left, game.outcome   # creatures penned, seconds left, "playing"/"won"/"lost"
    game.restart(world)             # back to the level's start, exactly

Its systems (`systems/herding/`) move the predator toward the aim and referee the
game; the sandbox's panel and the bot only aim and restart. Every aim is logged with
its frame (`log`), so a game replays from its inputs (`ecs_tentacles.herding.play`).
"""

from __future__ import annotations

import copy
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from ecs_tentacles.host import Host
    from ecs_tentacles.snapshot import Snapshot

PLAYING, WON, LOST = "playing", "won", "lost"


@dataclass
class GameState:
    """What changes as the game is played (snapshots copy it)."""

    predator: np.ndarray  # (2,) metres
    aim: np.ndarray  # (2,) where the player points it
    frames: int = 0  # game frames played (the clock stops when the game ends)
    penned: list[int] = field(default_factory=list)  # creature entities, in order
    penned_at: list[tuple[float, float, float]] = field(default_factory=list)  # where
    outcome: str = PLAYING
    log: list[tuple[int, float, float]] = field(default_factory=list)  # (frame, x, y)

    def copy(self) -> GameState:
        """A copy sharing nothing mutable (every field, whatever is added later)."""
        return copy.deepcopy(self)


class HerdingGame:
    """The level's rules (from the scene's `game`) and the game's state."""

    provided_by = "herding"

    def __init__(self, game: Mapping[str, Any], scene_name: str, fps: float):
        predator = game.get("predator") or {}
        self.level = str(game.get("level") or scene_name)
        self.pen_centre = np.asarray(game["pen"]["centre"], dtype=np.float64)
        self.pen_radius = float(game["pen"]["radius"])
        self.need = int(game["need"])
        self.seconds = float(game["seconds"])
        self.speed = float(predator.get("speed", 0.8))
        self.reach = float(predator.get("reach", 1.5))
        self.fps = float(fps)
        start = np.asarray(predator.get("position", (0.0, -3.0)), dtype=np.float64)
        self.state = GameState(start.copy(), start.copy())
        self.start: Snapshot | None = None  # the level's start (`ready`), not in snapshots

    # -- what the player does ------------------------------------------------------------
    def aim(self, world: Host, point: Sequence[float]) -> None:
        """Point the predator at `point` (x, y metres) from this frame on; logged."""
        x, y = float(point[0]), float(point[1])
        if not (np.isfinite(x) and np.isfinite(y)):
            raise ValueError(f"aim: ({x}, {y}) is not a point on the ground")
        self.state.aim = np.array([x, y])
        self.state.log.append((world.frame, x, y))

    def restart(self, world: Host) -> None:
        """Back to the level's start: the world as it was built, bit for bit."""
        if self.start is None:
            raise RuntimeError("the level has no start yet (the world is still being built)")
        world.restore(self.start)

    # -- what the HUD and the bot read ---------------------------------------------------
    @property
    def outcome(self) -> str:
        return self.state.outcome

    @property
    def penned(self) -> int:
        return len(self.state.penned)

    @property
    def elapsed(self) -> float:
        """Seconds of game time played."""
        return self.state.frames / self.fps

    @property
    def left(self) -> float:
        """Seconds left on the clock."""
        return max(0.0, self.seconds - self.elapsed)

    @property
    def predator(self) -> np.ndarray:
        return self.state.predator

    def in_pen(self, xy: np.ndarray) -> np.ndarray:
        """(n,) bool: points (n, 2) inside the pen."""
        return np.hypot(*(np.asarray(xy)[:, :2] - self.pen_centre).T) < self.pen_radius

    def summary(self) -> dict[str, Any]:
        """The game as a report gives it."""
        return {
            "level": self.level,
            "outcome": self.outcome,
            "penned": self.penned,
            "need": self.need,
            "seconds": round(self.elapsed, 3),
            "left": round(self.left, 3),
        }
