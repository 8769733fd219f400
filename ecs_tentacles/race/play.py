"""Running a race level without a window: a player, recorded inputs, replays.

    world = World.from_scene("race_1_rock")
    result = play(world, player)                 # until the race is won or lost
    again = play(World.from_scene(...), Replay(result["log"]))   # the same race, exactly

`play` steps the world, asking the player (anything with `decide(world, race)` ->
a list of points for the runner's path, or None to leave it) every `every` seconds,
until the race ends (or `max_seconds` of game time pass). It returns the race's
summary (`RaceGame.summary`), who took the flag, the input log and the wall time.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any, Protocol

from ecs_tentacles.game.modes import play_out
from ecs_tentacles.race.game import RaceGame

if TYPE_CHECKING:
    from ecs_tentacles.host import Host
    from ecs_tentacles.world import World


class Player(Protocol):
    def decide(self, world: Host, race: RaceGame) -> Sequence[Sequence[float]] | None: ...


class Replay:
    """Steers as a recorded log did, at the same frames."""

    def __init__(self, log: Sequence[tuple[int, float, float, bool]]):
        self.log = sorted(log, key=lambda entry: entry[0])  # stable: a frame's order kept
        self.next = 0

    def apply(self, world: World, race: RaceGame) -> int:
        """Steer what is due now; the frames until the next entry (0: none left)."""
        while self.next < len(self.log) and self.log[self.next][0] <= world.frame:
            _, x, y, add = self.log[self.next]
            race.steer(world, (x, y), add=add)
            self.next += 1
        return self.log[self.next][0] - world.frame if self.next < len(self.log) else 0


def play(
    world: World,
    player: Player | Replay,
    *,
    every: float = 0.5,
    max_seconds: float | None = None,
) -> dict[str, Any]:
    """Run the world's race to its end; its summary, `winner`, `log`, `wall_s`."""
    race = world.resource(RaceGame)

    def turn(block: int) -> int:
        if isinstance(player, Replay):
            wait = player.apply(world, race)
            return min(block, wait) if wait else block
        path = player.decide(world, race)
        if path:
            race.steer(world, path[0])
            for point in path[1:]:
                race.steer(world, point, add=True)
        return block

    limit = race.seconds if max_seconds is None else max_seconds
    wall_s, _ = play_out(world, race, limit, every, turn)
    return {
        **race.summary(),
        "winner": race.winner_name(world),
        "log": list(race.state.log),
        "wall_s": wall_s,
    }
