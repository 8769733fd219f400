"""`HerdingGame`: the herding game's state, a world resource (`world.resource(HerdingGame)`).

    game = world.resource(HerdingGame)
    game.aim(world, (1.0, 2.0))     # the player points the predator there (logged)
    game.run(world, True)           # the predator runs (farther reach, faster, tiring; logged)
    game.penned, game.left, game.outcome   # creatures penned, seconds left, "playing"/"won"/"lost"
    game.restart(world)             # back to the level's start, exactly

Its systems (`herding/systems/`) move the predator toward the aim and referee the
game; the sandbox's panel and the bot only aim and restart. Every aim is logged with
its frame (`log`), so a game replays from its inputs (`ecs_tentacles.herding.play`).
"""

from __future__ import annotations

import copy
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from ecs_tentacles.game.modes import PlayedGame

if TYPE_CHECKING:
    from ecs_tentacles.host import Host
    from ecs_tentacles.snapshot import Snapshot

PLAYING, WON, LOST = "playing", "won", "lost"
RECOVERED = 0.3  # the stamina a winded predator needs before it runs again
HERD_DEFAULTS = {
    "flee": 1.0,
    "graze": 0.4,
    "graze_share": 0.4,
    "flock_radius": 3.0,
    "cohesion": 1.0,
    "alignment": 0.5,
    "separation": 1.5,
    "interval": 1.0,
}  # the scene's `game.herd` (herding.schema.json gives the same defaults)


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
    heading: float = 0.0  # radians: the way the predator faces (where it last went)
    running: bool = False  # the player asks the predator to run
    stamina: float = 1.0  # 1: rested; running drains it, walking recovers it
    winded: bool = False  # ran out of stamina: walks until it has `RECOVERED` again
    runs: list[tuple[int, bool]] = field(default_factory=list)  # (frame, running) asked

    def copy(self) -> GameState:
        """A copy sharing nothing mutable (every field, whatever is added later)."""
        return copy.deepcopy(self)


class HerdingGame(PlayedGame):
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
        self.run_speed = float(predator.get("run_speed", 1.6))
        self.run_reach = float(predator.get("run_reach", 2.4))
        self.stamina_s = float(predator.get("stamina_s", 6.0))
        self.recover_s = float(predator.get("recover_s", 8.0))
        pen = game["pen"]
        self.gate_heading_deg = float((pen.get("gate") or {}).get("heading_deg", 180.0))
        self.gate_width = float((pen.get("gate") or {}).get("width", min(1.6, self.pen_radius)))
        self.fence_height = float((pen.get("fence") or {}).get("height", 0.5))
        self.par = float(game.get("par") or 0.5 * float(game["seconds"]))
        self.herd: dict[str, float] = {**HERD_DEFAULTS, **(game.get("herd") or {})}
        self.fps = float(fps)
        start = np.asarray(predator.get("position", (0.0, -3.0)), dtype=np.float64)
        self.state: GameState = GameState(start.copy(), start.copy())
        self.start: Snapshot | None = None  # the level's start (`ready`), not in snapshots

    # -- what the player does ------------------------------------------------------------
    def aim(self, world: Host, point: Sequence[float]) -> None:
        """Point the predator at `point` (x, y metres) from this frame on; logged."""
        x, y = float(point[0]), float(point[1])
        if not (np.isfinite(x) and np.isfinite(y)):
            raise ValueError(f"aim: ({x}, {y}) is not a point on the ground")
        self.state.aim = np.array([x, y])
        self.state.log.append((world.frame, x, y))

    def run(self, world: Host, running: bool) -> None:
        """The predator runs (True) or walks from this frame on; logged when it changes."""
        if bool(running) != self.state.running:
            self.state.running = bool(running)
            self.state.runs.append((world.frame, bool(running)))

    # -- what the HUD and the bot read ---------------------------------------------------
    @property
    def penned(self) -> int:
        return len(self.state.penned)

    @property
    def left(self) -> float:
        """Seconds left on the clock."""
        return max(0.0, self.seconds - self.elapsed)

    @property
    def predator(self) -> np.ndarray:
        return self.state.predator

    @property
    def sprinting(self) -> bool:
        """The predator runs now: asked to, and not winded."""
        return self.state.running and not self.state.winded

    @property
    def scare(self) -> float:
        """Metres: creatures closer than this to the predator flee (its reach now)."""
        return self.run_reach if self.sprinting else self.reach

    def stars(self) -> int:
        """Stars this game earned: 3 within par, 2 within 1.5x par, 1 for a win, else 0."""
        return stars_for(self.elapsed, self.par) if self.outcome == WON else 0

    def in_pen(self, xy: np.ndarray) -> np.ndarray:
        """(n,) bool: points (n, 2) inside the pen."""
        inside: np.ndarray = (
            np.hypot(*(np.asarray(xy)[:, :2] - self.pen_centre).T) < self.pen_radius
        )
        return inside

    def summary(self) -> dict[str, object]:
        """The game as a report gives it."""
        return {
            "level": self.level,
            "outcome": self.outcome,
            "penned": self.penned,
            "need": self.need,
            "seconds": round(self.elapsed, 3),
            "left": round(self.left, 3),
            "par": self.par,
            "stars": self.stars(),
        }


def stars_for(seconds: float, par: float) -> int:
    """Stars a win in `seconds` earns on a level of `par` seconds (1 to 3)."""
    return 3 if seconds <= par else 2 if seconds <= 1.5 * par else 1
