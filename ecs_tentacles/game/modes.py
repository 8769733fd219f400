"""The game layer's registry and data: what a game mode gives, what a game's result is.

    from ecs_tentacles.game.modes import GameMode, GameModes, GameResult

    class RacePlugin(Plugin):
        name = "race"
        requires = ("locomotion", "game")

        def build(self, app):
            app.add(GameModes, GameMode("race", RULES, race_result))

- `GameMode`: `name` (what `game.mode` says), `schema` (a JSON Schema object of the
  mode's other `game` keys: `properties`, `required`, defaults; `mode` is added), an
  optional `problems(scene)` for what the schema cannot say (on a scene whose `game`
  has the mode's defaults filled), and `result(world)` -> the `GameResult` now;
- `GameResult`: `outcome` (`PLAYING`, `WON`, `LOST`), game `seconds`, the `level`,
  `details` (the mode's counts for `--json`: penned, need...) and `text` (a phrase for
  `run`'s line). A result that is not `PLAYING` ends `run` and `play --headless`.

- `PlayedGame` and `Referee`: what every mode's game resource and referee system share
  (the level's start and restart, the outcome, the clock that runs while it is played);
  `play_out`: a bot's or a replay's game played to its end, a block of frames at a time.

No command, no GL: a feature imports it to register its mode.
"""

from __future__ import annotations

import time
from abc import ABC, abstractmethod
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Generic, Protocol, TypeVar

from ecs_tentacles.plugin import Problem
from ecs_tentacles.registry import Registry
from ecs_tentacles.system import System

if TYPE_CHECKING:
    from ecs_tentacles.host import Host
    from ecs_tentacles.snapshot import Snapshot
    from ecs_tentacles.world import World

PLAYING, WON, LOST = "playing", "won", "lost"


@dataclass(frozen=True)
class GameResult:
    """Where a game stands: `outcome` (PLAYING, WON or LOST) after `seconds` of game time."""

    outcome: str
    seconds: float
    level: str = ""
    details: Mapping[str, int | float | str] = field(default_factory=dict)
    text: str = ""

    @property
    def ended(self) -> bool:
        """Won or lost: the run stops here."""
        return self.outcome != PLAYING

    def report(self, mode: str) -> dict[str, object]:
        """The result as `--json` gives it: mode, level, outcome, seconds and the details."""
        return {
            "mode": mode,
            "level": self.level,
            "outcome": self.outcome,
            "seconds": round(self.seconds, 3),
            **self.details,
        }


@dataclass(frozen=True)
class GameMode:
    """A game mode a plugin registers (module docstring)."""

    name: str
    schema: Mapping[str, object]
    result: Callable[[Host], GameResult]
    problems: Callable[[Mapping[str, object]], list[Problem]] | None = None
    description: str = ""


class GameModes(Registry[GameMode]):
    """The modes the plugins on registered, by `GameMode.name`."""


class PlayState(Protocol):
    """What every game's state has: the game frames played and the outcome so far."""

    frames: int
    outcome: str


class PlayedGame:
    """What a game mode's resource shares: its `state` (with `frames` played and the
    `outcome`), the frame rate `fps`, and the level's `start` (a snapshot taken when the
    level is ready, not itself in snapshots)."""

    state: PlayState
    fps: float
    start: Snapshot | None = None

    def restart(self, world: Host) -> None:
        """Back to the level's start: the world as it was built, bit for bit."""
        if self.start is None:
            raise RuntimeError("the level has no start yet (the world is still being built)")
        world.restore(self.start)

    @property
    def outcome(self) -> str:
        return str(self.state.outcome)

    @property
    def elapsed(self) -> float:
        """Seconds of game time played."""
        return float(self.state.frames / self.fps)


G = TypeVar("G", bound=PlayedGame)


class Referee(System, ABC, Generic[G]):
    """A mode's referee (stage output): while its game is played, the clock moves a
    frame and `judge` decides from the mantles where things stand; once the game is won
    or lost, nothing. A mode's referee names its game (`played`) and judges."""

    stage = "output"
    reads = ("transforms.pos", "creatures.entity", "creatures.mantle_row")
    writes = ()

    @abstractmethod
    def played(self, world: Host) -> G:
        """The game this referee keeps (its mode's resource)."""

    @abstractmethod
    def judge(self, world: Host, game: G) -> None:
        """After the frame `game.state.frames` counts: penned, arrived, won or lost."""

    def process(self, world: Host, dt: float) -> None:
        game = self.played(world)
        if game.state.outcome != PLAYING:
            return
        game.state.frames += 1
        self.judge(world, game)


def play_out(
    world: World,
    game: PlayedGame,
    seconds: float,
    every: float,
    turn: Callable[[int], int],
) -> tuple[float, list[float]]:
    """Step `world` until `game` is won or lost (or `seconds` of world time and one more
    pass), `every` seconds of frames at a time: `turn(block)` moves the player and says
    how many frames to step (`block`, or fewer to the next replayed move). Returns the
    wall seconds taken and each step's milliseconds per frame."""
    block = max(1, round(every * world.settings.fps))
    started = time.perf_counter()
    frame_ms: list[float] = []
    while game.outcome == PLAYING and world.time < seconds + 1.0:
        frames = turn(block)
        before = time.perf_counter()
        world.step(frames)
        frame_ms.append(1000.0 * (time.perf_counter() - before) / frames)
    return round(time.perf_counter() - started, 2), frame_ms
