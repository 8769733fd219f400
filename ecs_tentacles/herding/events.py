"""The herding game's events (`ecs_tentacles.events`): subscribe by class or by name.

world.events.on(GameWon, lambda event: print(event.seconds))
world.events.on("creature_penned", lambda **event: print(event["creature"]))
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from ecs_tentacles.events import CreatureEvent, Event


@dataclass(frozen=True)
class CreaturePenned(CreatureEvent):
    """Creature `creature` entered the pen at game time `seconds`; `penned` so far."""

    name: ClassVar[str] = "creature_penned"
    seconds: float
    penned: int


@dataclass(frozen=True)
class CreatureLeft(CreatureEvent):
    """Penned creature `creature` was driven out of the pen at game time `seconds`."""

    name: ClassVar[str] = "creature_left"
    seconds: float


@dataclass(frozen=True)
class GameOver(Event):
    """The game ended at game time `seconds` with `penned` creatures in the pen."""

    seconds: float
    penned: int


@dataclass(frozen=True)
class GameWon(GameOver):
    """Enough creatures are penned: won in `seconds` of game time."""

    name: ClassVar[str] = "game_won"


@dataclass(frozen=True)
class GameLost(GameOver):
    """The time ran out with `penned` creatures in the pen, `need` needed."""

    name: ClassVar[str] = "game_lost"
    need: int
