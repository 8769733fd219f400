"""The herding game's events (`ecs_tentacles.events`): subscribe by class or by name.

world.events.on(GameWon, lambda event: print(event.seconds))
world.events.on("creature_penned", lambda **event: print(event["creature"]))
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from ecs_tentacles.events import Event


@dataclass(frozen=True)
class CreaturePenned(Event):
    """Creature `creature` entered the pen at game time `seconds`; `penned` so far."""

    name: ClassVar[str] = "creature_penned"
    creature: int
    seconds: float
    penned: int


@dataclass(frozen=True)
class CreatureLeft(Event):
    """Penned creature `creature` was driven out of the pen at game time `seconds`."""

    name: ClassVar[str] = "creature_left"
    creature: int
    seconds: float


@dataclass(frozen=True)
class GameWon(Event):
    """Enough creatures are penned: won in `seconds` of game time."""

    name: ClassVar[str] = "game_won"
    seconds: float
    penned: int


@dataclass(frozen=True)
class GameLost(Event):
    """The time ran out with `penned` creatures in the pen, `need` needed."""

    name: ClassVar[str] = "game_lost"
    seconds: float
    penned: int
    need: int
