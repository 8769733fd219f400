"""Formations: a goal for each of several creatures gathered round one point.

    slots = formation_goals(world, creatures, point, "ring")   # (n, 2), one per creature
    for creature, slot in zip(creatures, slots): book.set(creature, slot)

Slots are `spacing(reaches)` apart: twice the largest reach among the creatures (mantle
radius plus its longest tentacle) and `GAP`, so creatures that arrive with their
tentacles spread do not touch (crowd avoidance keeps the same personal circles apart).
A formation is as small as its group: it takes the slots nearest the point first and only
as many as there are creatures. Shapes (`SHAPES`):

* `ring`: rings around the point (the first one a spacing out, each next one a spacing
  further), inner rings filled first; the outermost ring's creatures spread evenly
  round it;
* `grid`: rows and columns centred on the point, rows facing the way the group comes
  (a block of about as many rows as columns), then the places next to the block;
* `line`: one row through the point, across the way the group comes; a row cut short
  (an obstacle, the heightfield's edge) goes on in a second row behind the first (then
  one before it, and so on, in turn).

A slot must be reachable: none within half a spacing of an obstacle, and when the point
is on a heightfield, none whose creature would stand past its edge (it would drop off);
the next slot in order takes its place. Which creature takes which slot is the
assignment with the least total distance (`scipy.optimize.linear_sum_assignment`), so
paths do not cross more than they must. The sandbox's goal clicks use this when several
creatures are selected; the shape is the Locomotion section's "formation" choice
(`FormationChoice`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.components import Creature, Transform
from ecs_tentacles.ground import ground_of

if TYPE_CHECKING:
    from ecs_tentacles.host import Host

SHAPES = ("ring", "grid", "line")
GAP = 0.1  # metres between two creatures' reaches in a formation
FARTHEST = 64  # rings (or rows) tried outward before a formation gives up


class FormationChoice:
    """`world.resource(FormationChoice).shape`: the shape group goals take (HUD choice)."""

    provided_by = "locomotion"

    def __init__(self) -> None:
        self.shape = "ring"


def reach(world: Host, creature: int) -> float:
    """How far creature `creature` reaches from its mantle's axis: its mantle radius
    and its longest tentacle (metres)."""
    body = world.component(creature, Creature)
    first = int(world.creatures.first_tentacle[body.row])
    rows = np.arange(first, first + int(world.creatures.tentacles[body.row]))
    longest = float(world.tentacles.length[rows].max()) if len(rows) else 0.0
    return float(body.mantle_radius) + longest


def spacing(reaches: Sequence[float]) -> float:
    """Centre-to-centre distance of neighbouring slots for creatures of `reaches`."""
    return 2.0 * float(max(reaches)) + GAP


Usable = Callable[[np.ndarray], np.ndarray]  # slots (k, 2) -> (k,) bool


def _everywhere(points: np.ndarray) -> np.ndarray:
    return np.ones(len(points), dtype=bool)


def _gathered(count: int, tiers: range, pick: Callable[[int, int], np.ndarray]) -> np.ndarray:
    """Places (k, 2) from `tiers` in turn, `pick(tier, need)` choosing at most `need` of a
    tier's usable places, until `count` are found (fewer when the tiers run out)."""
    taken: list[np.ndarray] = []
    need = count
    for tier in tiers:
        chosen = pick(tier, need)
        taken.append(chosen)
        need -= len(chosen)
        if need == 0:
            break
    return np.vstack(taken)


def _ring(count: int, centre: np.ndarray, step: float, usable: Usable) -> np.ndarray:
    def pick(ring: int, need: int) -> np.ndarray:
        radius = ring * step
        places = max(1, int(np.floor(2.0 * np.pi * radius / step)))
        angle = np.arange(places) * 2.0 * np.pi / places + 0.5 * ring
        on_ring = centre + radius * np.column_stack([np.cos(angle), np.sin(angle)])
        free = on_ring[usable(on_ring)]
        if len(free) > need:  # the outermost ring: spread evenly round it
            free = free[np.floor(np.arange(need) * len(free) / need).astype(np.int64)]
        return free

    return _gathered(count, range(1, FARTHEST + 1), pick)


def _line(
    count: int, centre: np.ndarray, step: float, facing: np.ndarray, usable: Usable
) -> np.ndarray:
    across = np.array([-facing[1], facing[0]])
    offsets = np.arange(count) - (count - 1) / 2.0

    def pick(row: int, need: int) -> np.ndarray:
        back = (row + 1) // 2 if row % 2 else -(row // 2)
        places: np.ndarray = centre + (offsets[:, None] * across - back * facing) * step
        free = np.flatnonzero(usable(places))
        free = np.sort(free[np.argsort(np.abs(offsets[free]), kind="stable")][:need])
        return places[free]  # the usable places nearest the middle, in a row

    # rows behind (toward the group), then before, in turn
    return _gathered(count, range(2 * FARTHEST), pick)


def _grid(
    count: int, centre: np.ndarray, step: float, facing: np.ndarray, usable: Usable
) -> np.ndarray:
    columns = int(np.ceil(np.sqrt(count)))
    rows = int(np.ceil(count / columns))
    across = np.array([-facing[1], facing[0]])
    # the block's lattice, reaching `FARTHEST` places either way of it
    j = np.arange(-FARTHEST, columns + FARTHEST) - (columns - 1) / 2.0
    i = np.arange(-FARTHEST, rows + FARTHEST) - (rows - 1) / 2.0
    jj, ii = (a.ravel() for a in np.meshgrid(j, i))
    places = centre + (jj[:, None] * across - ii[:, None] * facing) * step
    in_block = (np.abs(jj) <= (columns - 1) / 2.0 + 1e-9) & (np.abs(ii) <= (rows - 1) / 2.0 + 1e-9)
    near = np.hypot(jj, ii)
    order = np.lexsort((near, ~in_block))  # the block first, nearest the point first
    places = places[order]

    def pick(start: int, need: int) -> np.ndarray:
        batch: np.ndarray = places[start : start + 4 * count]
        return batch[usable(batch)][:need]

    # a batch at a time: tests cost
    return _gathered(count, range(0, len(places), 4 * count), pick)


def slots(
    shape: str,
    count: int,
    centre: np.ndarray,
    step: float,
    facing: np.ndarray,
    usable: Usable = _everywhere,
) -> np.ndarray:
    """`count` slot centres (count, 2) of `shape`, `step` apart, around `centre`, each
    one `usable` (fewer when none is left within `FARTHEST` steps); `facing` (unit, 2) is
    the way the group comes (rows and lines lie across it)."""
    if shape not in SHAPES:
        raise ValueError(f"formation: must be one of {', '.join(SHAPES)}, got {shape!r}")
    centre = np.asarray(centre, dtype=np.float64)
    if count <= 0:
        return np.zeros((0, 2))
    if shape == "ring":
        return _ring(count, centre, step, usable)
    if shape == "grid":
        return _grid(count, centre, step, facing, usable)
    return _line(count, centre, step, facing, usable)


def _reachable(world: Host, centre: np.ndarray, step: float, reach: float) -> Usable:
    """Which slots a creature can stand on: clear of obstacles by half a `step`, and on
    the heightfield (its whole `reach` circle) when `centre` is."""
    ground = ground_of(world)
    extent = ground.extent
    half = None
    if extent is not None:
        half = extent - reach
        if (np.abs(centre) > half).any():
            half = None  # clicked past the edge: the group goes there

    def usable(points: np.ndarray) -> np.ndarray:
        ok = np.ones(len(points), dtype=bool)
        if half is not None:
            ok &= (np.abs(points) <= half).all(axis=1)
        if ground.has_obstacles and ok.any():
            raised = np.column_stack([points[ok], ground.surface(points[ok])])
            ok[ok] = ground.inside_solid(raised, 0.5 * step) < 0
        return ok

    return usable


def formation_goals(
    world: Host, creatures: Sequence[int], point: Sequence[float] | np.ndarray, shape: str
) -> np.ndarray:
    """A goal (n, 2) for each of `creatures` in `shape` around `point` (module doc)."""
    if shape not in SHAPES:
        raise ValueError(f"formation: must be one of {', '.join(SHAPES)}, got {shape!r}")
    centre = np.asarray(point, dtype=np.float64)[:2]
    where = np.array([world.component(c, Transform).pos[:2] for c in creatures]).reshape(-1, 2)
    if len(creatures) == 1:
        return centre[None].copy()
    reaches = [reach(world, c) for c in creatures]
    step = spacing(reaches)
    coming = centre - where.mean(axis=0)
    norm = float(np.linalg.norm(coming))
    facing = coming / norm if norm > 1e-9 else np.array([1.0, 0.0])
    wanted = len(creatures)
    made = slots(shape, wanted, centre, step, facing, _reachable(world, centre, step, max(reaches)))
    if len(made) < wanted:
        raise ValueError(f"no room for a {shape} of {wanted} creatures around {centre.tolist()}")
    cost = np.linalg.norm(where[:, None, :] - made[None, :, :], axis=2)
    from scipy.optimize import linear_sum_assignment  # here: a slow import

    rows, columns = linear_sum_assignment(cost)
    out = np.empty((wanted, 2))
    out[rows] = made[columns]
    return out
