"""Where a creature may be sent in a herding level: open ground, the fence respected.

    goals, found = open_goals(world, fence, starts, directions, metres, crossing)

For each creature (row) the goal `metres` ahead of `starts` along its wished
`directions` (n, 2), or, when that is blocked, along the nearest direction turned
away from it (30 degrees at a time, either way, up to straight back) that is open: the
goal and the points a third and two thirds of the way clear of every obstacle by
`CLEARANCE` m (`Ground.inside_solid`), on the shaped ground (its `extent`), and the way
there crossing no fence but through the gate (`Fence.crossing_ok`), and only where
`crossing` allows it at all. `found` says which rows have one (the others: none open).

Reads: the world's ground (`ground_of`). Writes: nothing.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.ground import ground_of
from ecs_tentacles.herding.fence import CLEAR

if TYPE_CHECKING:
    from ecs_tentacles.herding.fence import Fence
    from ecs_tentacles.host import Host

CLEARANCE = 0.35  # metres: a creature's body and a margin, between its goal and a wall
TURNS = np.radians([0, 30, -30, 60, -60, 90, -90, 120, -120, 150, -150, 180])
ALONG = (1 / 3, 2 / 3, 1.0)  # points of the way checked against obstacles


def open_ground(world: Host, xy: np.ndarray) -> np.ndarray:
    """(m,) bool: points (m, 2) on open ground (off every obstacle by `CLEARANCE` m,
    on the shaped ground)."""
    ground = ground_of(world)
    ok = np.ones(len(xy), dtype=bool)
    extent = ground.extent
    if extent is not None:
        ok &= (np.abs(xy) <= np.asarray(extent) - CLEARANCE).all(axis=1)
    if ground.has_obstacles and len(xy):
        points = np.column_stack([xy, ground.height(xy) + 0.5 * CLEARANCE])
        ok &= ground.inside_solid(points, CLEARANCE) < 0
    return ok


def open_goals(
    world: Host,
    fence: Fence,
    starts: np.ndarray,
    directions: np.ndarray,
    metres: np.ndarray | float,
    crossing: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """Goals (n, 2) and whether each was found (n,): the wished direction's, or the
    nearest open one's (module docstring)."""
    n, k = len(starts), len(TURNS)
    if n == 0:
        return np.zeros((0, 2)), np.zeros(0, dtype=bool)
    angle = np.arctan2(directions[:, 1], directions[:, 0])[:, None] + TURNS[None, :]  # (n, k)
    unit = np.stack([np.cos(angle), np.sin(angle)], axis=2)
    reach = np.broadcast_to(np.asarray(metres, dtype=np.float64), (n,))[:, None, None]
    origin = np.repeat(starts[:, None, :], k, axis=1)
    goals = origin + reach * unit  # (n, k, 2)
    # a goal inside the pen is kept off its fence (drawn in toward the centre)
    off = goals - fence.centre
    gap = np.linalg.norm(off, axis=2, keepdims=True)
    room = max(fence.radius - CLEAR, 0.0)
    goals = np.where(
        gap < fence.radius,
        fence.centre + off * np.minimum(1.0, room / np.maximum(gap, 1e-9)),
        goals,
    )
    flat_origin, flat_goals = origin.reshape(-1, 2), goals.reshape(-1, 2)
    ok = fence.crossing_ok(flat_origin, flat_goals)
    same_side = fence.inside(flat_origin) == fence.inside(flat_goals)
    ok &= same_side | np.repeat(crossing, k)
    for t in ALONG:
        ok &= open_ground(world, flat_origin + t * (flat_goals - flat_origin))
    ok = ok.reshape(n, k)
    found = ok.any(axis=1)
    first = np.argmax(ok, axis=1)
    return goals[np.arange(n), first], np.asarray(found, dtype=bool)
