"""The race mode's event (`ecs_tentacles.events`): subscribe by class or by name.

world.events.on(RaceFinished, lambda event: print(event.outcome, event.seconds))
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from ecs_tentacles.events import Event


@dataclass(frozen=True)
class RaceFinished(Event):
    """The race ended at game time `seconds`: `outcome` "won" or "lost" for the player;
    `winner` the creature that reached the flag first (-1: the time ran out)."""

    name: ClassVar[str] = "race_finished"
    outcome: str
    seconds: float
    winner: int
