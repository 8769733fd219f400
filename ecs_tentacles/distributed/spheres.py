"""contact_spheres: each creature's bounding sphere every simulated frame, as the
contact proxies see it, and the check that creatures of different shards never met.

A shard's bake adds `ContactSpheres` (a system, not one of the built-ins). Reads:
the Transform store (every mantle and link), the bodies' radius and length. Writes:
its own array `spheres` (frames + 1, creatures, 4): centre x, y, z and radius, in the
world's creature order, frame 0 the built pose. Runs after physics_sync.

`meetings` then finds creatures of different shards whose spheres came within the
proxies' `MARGIN` in the same frame, or whose mantles came within the distance at which
a plugin lets them act on each other without touching (`Plugin.meeting_reach`: crowd
avoidance): exactly when a local bake would have given them proxies of each other, or
steered them, so a bake with no meetings equals the local bake.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.components import Creature, Link, Tentacle, Transform
from ecs_tentacles.physics.proxies import MARGIN
from ecs_tentacles.system import System

if TYPE_CHECKING:
    from ecs_tentacles.host import Host


class ContactSpheres(System):
    """Record every creature's contact sphere each frame into `self.spheres`."""

    name = "contact_spheres"
    after = ("physics_sync",)

    def __init__(self, steps: int):
        self.steps = steps
        self.spheres = np.zeros((0, 0, 4))
        self._frame = 0

    def setup(self, world: Host) -> None:
        rows, owner, bound = [], [], []
        creatures = sorted(world.query(Creature), key=lambda item: item[1].row)
        for index, (entity, creature) in enumerate(creatures):
            rows.append(world.component(entity, Transform).row)
            owner.append(index)
            bound.append(float(np.hypot(creature.mantle_radius, 0.5 * creature.mantle_height)))
            for tentacle_entity in creature.tentacles:
                for link_entity in world.component(tentacle_entity, Tentacle).links:
                    link = world.component(link_entity, Link)
                    rows.append(world.component(link_entity, Transform).row)
                    owner.append(index)
                    bound.append(link.radius + 0.5 * link.length)
        self.rows = np.asarray(rows, dtype=np.int64)
        self.owner = np.asarray(owner, dtype=np.int64)
        self.bound = np.asarray(bound)
        self.start = np.flatnonzero(np.r_[True, self.owner[1:] != self.owner[:-1]])
        self.spheres = np.zeros((self.steps + 1, len(creatures), 4))
        self._frame = 0
        self._capture(world)

    def _capture(self, world: Host) -> None:
        if self._frame >= len(self.spheres) or not len(self.rows):
            return
        pos = world.transforms.pos[self.rows]
        centre = pos[self.start]
        reach = np.linalg.norm(pos - centre[self.owner], axis=1) + self.bound
        self.spheres[self._frame, :, :3] = centre
        self.spheres[self._frame, :, 3] = np.maximum.reduceat(reach, self.start)
        self._frame += 1

    def process(self, world: Host, dt: float) -> None:
        self._capture(world)


def meetings(
    spheres: np.ndarray, shard_of: np.ndarray, reach: np.ndarray | None = None
) -> list[tuple[int, int, int]]:
    """(creature i, creature j, first frame) for creatures of different shards that met.

    `spheres` (frames, creatures, 4) in scene order, centred on each mantle; `shard_of`
    the shard of each creature; `reach` (creatures,) how far from its mantle, on the
    ground, each acts on others without touching (`Plugin.meeting_reach`): two also
    meet when their mantles come within the sum of their reaches.
    """
    centre, radius = spheres[..., :3], spheres[..., 3]
    start = centre[0]
    extent = (np.linalg.norm(centre - start, axis=2) + radius).max(axis=0)
    acts = np.zeros(len(start)) if reach is None else np.asarray(reach, dtype=np.float64)
    travel = np.linalg.norm(centre[..., :2] - start[:, :2], axis=2).max(axis=0)
    found: list[tuple[int, int, int]] = []
    n = len(start)
    block = max(1, 2_000_000 // max(n, 1))
    for lo in range(0, n, block):
        hi = min(n, lo + block)
        gap = np.linalg.norm(start[lo:hi, None] - start[None], axis=2)
        touch = gap - (extent[lo:hi, None] + extent[None]) < MARGIN
        flat = np.linalg.norm(start[lo:hi, None, :2] - start[None, :, :2], axis=2)
        steer = flat - (travel + acts)[lo:hi, None] - (travel + acts)[None] < 0.0
        i, j = np.nonzero(touch | steer)
        i += lo
        keep = (i < j) & (shard_of[i] != shard_of[j])
        for a, b in zip(i[keep].tolist(), j[keep].tolist(), strict=True):
            distance = np.linalg.norm(centre[:, a] - centre[:, b], axis=1)
            close = distance - radius[:, a] - radius[:, b] < MARGIN
            if reach is not None:
                ground = np.linalg.norm(centre[:, a, :2] - centre[:, b, :2], axis=1)
                close |= ground < acts[a] + acts[b]
            frames = np.flatnonzero(close)
            if len(frames):
                found.append((a, b, int(frames[0])))
    return found
