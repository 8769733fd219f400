"""`RaceGame`: the race's state, a world resource (`world.resource(RaceGame)`).

    race = world.resource(RaceGame)
    race.steer(world, (2.0, 1.5))             # the runner goes there (the path is that point)
    race.steer(world, (4.0, 1.5), add=True)   # and then there (a waypoint added)
    race.outcome, race.left, race.winner      # "playing"/"won"/"lost", seconds left, who
    race.restart(world)                       # back to the level's start, exactly

Its systems (`race/systems/`) move the runner along its path and the rivals to the
flag, and referee the race; the sandbox's panel and a headless player only steer and
restart. Every input is logged with its frame (`log`), so a race replays from its
inputs (`ecs_tentacles.race.play`).
"""

from __future__ import annotations

import copy
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.game.modes import PLAYING, PlayedGame

if TYPE_CHECKING:
    from ecs_tentacles.host import Host
    from ecs_tentacles.snapshot import Snapshot

NOBODY = -1


@dataclass
class RaceState:
    """What changes as the race is run (snapshots copy it)."""

    path: list[tuple[float, float]] = field(default_factory=list)  # the runner's waypoints
    sent: tuple[float, float] | None = None  # the waypoint the runner was sent to
    rivals_off: bool = False  # the rivals were sent to the flag
    frames: int = 0  # race frames run (the clock stops when the race ends)
    outcome: str = PLAYING
    winner: int = NOBODY  # the creature that reached the flag first (entity)
    log: list[tuple[int, float, float, bool]] = field(default_factory=list)  # frame, x, y, add

    def copy(self) -> RaceState:
        """A copy sharing nothing mutable."""
        return copy.deepcopy(self)


def _number(rules: Mapping[str, object], key: str) -> float:
    value = rules[key]
    if not isinstance(value, (int, float)):
        raise TypeError(f"game.{key}: a number, not {value!r}")
    return float(value)


class RaceGame(PlayedGame):
    """The level's rules (the scene's `game`, defaults filled) and the race's state."""

    provided_by = "race"

    def __init__(self, rules: Mapping[str, object], scene_name: str, fps: float):
        flag = rules["flag"]
        if not isinstance(flag, Mapping):
            raise TypeError(f"game.flag: an object, not {flag!r}")
        self.level = str(rules.get("level") or scene_name)
        self.runner_name = str(rules["runner"])
        self.flag = np.asarray(flag["position"], dtype=np.float64)
        self.radius = float(flag["radius"])
        self.seconds = _number(rules, "seconds")
        self.rivals_wait = _number(rules, "rivals_wait")
        self.fps = float(fps)
        self.runner = NOBODY  # the runner's entity, once the creatures are built
        self.state: RaceState = RaceState()
        self.start: Snapshot | None = None  # the level's start (`ready`), not in snapshots

    # -- what the player does ------------------------------------------------------------
    def steer(self, world: Host, point: Sequence[float], *, add: bool = False) -> None:
        """Send the runner to `point` (x, y metres), or (`add`) to it after its path."""
        x, y = float(point[0]), float(point[1])
        if not (np.isfinite(x) and np.isfinite(y)):
            raise ValueError(f"steer: ({x}, {y}) is not a point on the ground")
        if add:
            self.state.path.append((x, y))
        else:
            self.state.path = [(x, y)]
            self.state.sent = None  # sent again, even to the same point
        self.state.log.append((world.frame, x, y, add))

    # -- what the HUD and a player read --------------------------------------------------

    @property
    def left(self) -> float:
        """Seconds left on the clock."""
        return max(0.0, self.seconds - self.elapsed)

    @property
    def winner(self) -> int:
        """The creature that reached the flag first (entity; NOBODY yet or on time out)."""
        return self.state.winner

    def winner_name(self, world: Host) -> str:
        """The name of the creature that reached the flag first ("" if none yet)."""
        return "" if self.winner == NOBODY else world.creature_name(self.winner)

    def at_flag(self, xy: np.ndarray) -> np.ndarray:
        """(n,) bool: points (n, 2+) inside the flag's ring."""
        inside: np.ndarray = np.hypot(*(np.asarray(xy)[:, :2] - self.flag).T) < self.radius
        return inside

    def summary(self) -> dict[str, object]:
        """The race as a report gives it."""
        return {
            "level": self.level,
            "outcome": self.outcome,
            "seconds": round(self.elapsed, 3),
            "left": round(self.left, 3),
        }
