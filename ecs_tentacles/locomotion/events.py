"""The locomotion plugin's events (`ecs_tentacles.events`): subscribe by class or by name.

world.events.on(GoalReached, lambda event: print(event.creature, event.position))
world.events.on("goal_reached", lambda **event: print(event["position"]))
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from ecs_tentacles.events import CreatureEvent, SuckerEvent


@dataclass(frozen=True)
class GoalReached(CreatureEvent):
    """A creature reached goal entity `goal` at `position` (the goal is gone now)."""

    name: ClassVar[str] = "goal_reached"
    goal: int
    position: np.ndarray


@dataclass(frozen=True)
class SuckerAttached(SuckerEvent):
    """A sucker attached at `anchor` (world metres)."""

    name: ClassVar[str] = "sucker_attached"
    anchor: np.ndarray
