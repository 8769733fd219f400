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

Pure data (no command, no GL): a feature imports it to register its mode.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from ecs_tentacles.registry import Registry

if TYPE_CHECKING:
    from ecs_tentacles.host import Host

PLAYING, WON, LOST = "playing", "won", "lost"
Problem = tuple[tuple[str | int, ...], str]


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

    def report(self, mode: str) -> dict[str, Any]:
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
    schema: Mapping[str, Any]
    result: Callable[[Host], GameResult]
    problems: Callable[[Mapping[str, Any]], list[Problem]] | None = None
    description: str = ""


class GameModes(Registry[GameMode]):
    """The modes the plugins on registered, by `GameMode.name`."""
