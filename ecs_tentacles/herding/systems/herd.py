"""herd: the herding game's creatures flee the predator, graze, and keep together.

Every `game.herd.interval` seconds (stage decide), for every creature at once:
- fleeing: a creature closer to the predator than its reach (`HerdingGame.scare`: the
  walking or the running reach) heads `flee` metres away from it (1.5 times that from
  a running predator), bent a little toward its flock (a flock flees as one);
- grazing: the others, the idle ones, drift as a loose flock: toward the centre of
  the creatures within `flock_radius` on their side of the fence (cohesion), the way
  they go (alignment), apart from any closer than 0.8 m (separation), plus a grazing
  wander; a share (`graze_share`) of them take a `graze` metre step at each plan,
  chosen by a generator seeded from the scene's seed and the frame (a restart and a
  replay graze alike), the rest stand and graze.
Every goal is on open ground and respects the fence (`ecs_tentacles.herding.open_ground`):
blocked, a creature turns to the nearest open direction (along a wall, never into it);
only a fleeing creature crosses the pen's circle, and only through the gate. So a
penned creature stays penned unless the predator drives it out, and one outside comes
in only when driven.

Reads: `HerdingGame` (predator, reach, herd settings), the world's ground, CreatureStore
(mantle_row, entity), Transform store (mantle positions). Writes: goals, through
`travel(world).send` (`ecs_tentacles.behaviour`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.behaviour import DestinationSystem, travel
from ecs_tentacles.herding.fence import Fence
from ecs_tentacles.herding.game import HerdingGame
from ecs_tentacles.herding.open_ground import open_goals
from ecs_tentacles.numeric.vectors import unit_rows

if TYPE_CHECKING:
    from ecs_tentacles.host import Host
    from ecs_tentacles.roster_change import RosterChange

APART = 0.8  # metres: closer creatures push apart
CRAWL = 0.1  # m/s: a flock going this fast aligns a creature fully
GOAL_RADIUS = 0.3  # metres: a goal is reached within this
RUN_FLEE = 1.5  # a running predator's flight goals lie this much farther
TOWARD_FLOCK = 0.15  # how much a fleeing creature bends toward its flock


class Herd(DestinationSystem):
    """Flee the predator, else graze as a loose flock; goals on open ground."""

    name = "herding_herd"
    reads = ("transforms.pos", "creatures.entity", "creatures.mantle_row")
    state_attributes = ("last",)  # positions at the last plan: velocities after a restore

    def __init__(self) -> None:
        self.every = 1
        self.last: np.ndarray | None = None
        self.seed = 0

    def setup(self, world: Host) -> None:
        game = world.resource(HerdingGame)
        self.every = max(1, round(game.herd["interval"] * world.settings.fps))
        self.seed = int((world.scene or {}).get("seed") or 0)

    def roster_changed(self, world: Host, change: RosterChange) -> None:
        if self.last is not None:  # a newcomer starts still
            mantle = world.transforms.pos[world.creatures.mantle_row[-1:], :2]
            self.last = change.follow(self.last, "creatures", mantle)

    def flock(
        self, pos: np.ndarray, vel: np.ndarray, side: np.ndarray, herd: dict[str, float]
    ) -> tuple[np.ndarray, np.ndarray]:
        """(n, 2) the idle steering (cohesion, alignment, separation), and (n, 2) the
        direction to each creature's flock centre (zero alone)."""
        offset = pos[:, None, :] - pos[None, :, :]
        gap = np.linalg.norm(offset, axis=2)
        np.fill_diagonal(gap, np.inf)
        near = (gap < herd["flock_radius"]) & (side[:, None] == side[None, :])
        count = np.maximum(near.sum(axis=1), 1)[:, None]
        centre = np.where(near.any(axis=1)[:, None], (near @ pos) / count - pos, 0.0)
        cohere = centre / herd["flock_radius"]
        align = (near @ vel) / count / CRAWL
        align /= np.maximum(np.linalg.norm(align, axis=1, keepdims=True), 1.0)
        push = np.where(gap < APART, APART / np.maximum(gap, 1e-9) - 1, 0.0)
        separate = np.einsum("ij,ijk->ik", push / np.maximum(gap, 1e-9), offset)
        steer = herd["cohesion"] * cohere + herd["alignment"] * align
        return steer + herd["separation"] * separate, unit_rows(centre)

    def process(self, world: Host, dt: float) -> None:
        if world.frame % self.every:
            return
        game = world.resource(HerdingGame)
        creatures = world.creatures
        if not creatures.count:
            return
        herd = game.herd
        fence = Fence.of(game)
        pos = world.transforms.pos[creatures.mantle_row, :2].copy()
        seconds = self.every * dt
        vel = np.zeros_like(pos) if self.last is None else (pos - self.last) / seconds
        self.last = pos
        side = fence.inside(pos)
        steer, to_flock = self.flock(pos, vel, side, herd)
        away = pos - game.predator[None, :]
        gap = np.hypot(*away.T)
        fleeing = gap < game.scare
        rng = np.random.default_rng([self.seed, world.frame])
        wander = rng.normal(size=pos.shape)
        grazing = ~fleeing & (rng.random(len(pos)) < herd["graze_share"])
        moving = fleeing | grazing
        direction = np.where(
            fleeing[:, None],
            unit_rows(away) + TOWARD_FLOCK * to_flock,
            steer + 0.7 * unit_rows(wander),
        )
        metres = np.where(fleeing, herd["flee"] * (RUN_FLEE if game.sprinting else 1.0), 0.0)
        metres = np.where(grazing, herd["graze"], metres)
        rows = np.flatnonzero(moving & (np.linalg.norm(direction, axis=1) > 1e-9))
        goals, found = open_goals(
            world, fence, pos[rows], direction[rows], metres[rows], fleeing[rows]
        )
        send = travel(world).send
        for row, goal in zip(rows[found].tolist(), goals[found], strict=True):
            send(world, int(creatures.entity[row]), goal, GOAL_RADIUS)
