"""Formations: a goal for each of several creatures around one point, spaced by reach.

    slots = formation_goals(world, creatures, point, "ring")   # (n, 2), one per creature
    for creature, slot in zip(creatures, slots): book.set(creature, slot)

Slots are `spacing(reaches)` apart: twice the largest reach among the creatures (mantle
radius plus its longest tentacle) and `GAP`, so creatures that arrive with their
tentacles spread do not touch. Shapes (`SHAPES`):

* `ring`: rings around the point (the first one reach out, each next one a spacing
  further), filled inner ring first;
* `grid`: rows and columns centred on the point, rows facing the way the group comes;
* `line`: one row through the point, across the way the group comes.

Which creature takes which slot is the assignment with the least total distance
(`scipy.optimize.linear_sum_assignment`), so paths do not cross more than they must.
Slots inside an obstacle are not used (more are made). The sandbox's goal clicks use
this when several creatures are selected; the shape is the Locomotion section's
"formation" choice (`FormationChoice`).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
from scipy.optimize import linear_sum_assignment

from ecs_tentacles.components import Creature, Transform
from ecs_tentacles.ground import ground_of

if TYPE_CHECKING:
    from ecs_tentacles.host import Host

SHAPES = ("ring", "grid", "line")
GAP = 0.1  # metres between two creatures' reaches in a formation


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


def slots(
    shape: str, count: int, centre: np.ndarray, step: float, facing: np.ndarray
) -> np.ndarray:
    """At least `count` slot centres (k, 2) of `shape`, `step` apart, around `centre`;
    `facing` (unit, 2) is the way the group comes (rows and lines lie across it)."""
    if shape not in SHAPES:
        raise ValueError(f"formation: must be one of {', '.join(SHAPES)}, got {shape!r}")
    across = np.array([-facing[1], facing[0]])
    if shape == "line":
        offsets = (np.arange(count) - (count - 1) / 2.0)[:, None] * step * across
        return centre + offsets
    if shape == "grid":
        columns = int(np.ceil(np.sqrt(count)))
        rows = int(np.ceil(count / columns))
        i, j = np.divmod(np.arange(rows * columns), columns)
        offsets = ((j - (columns - 1) / 2.0)[:, None] * across
                   - (i - (rows - 1) / 2.0)[:, None] * facing) * step  # fmt: skip
        return centre + offsets
    points: list[np.ndarray] = []
    ring = 1
    while sum(len(p) for p in points) < count:
        radius = ring * step
        places = max(1, int(np.floor(2.0 * np.pi * radius / step)))
        angle = np.arange(places) * 2.0 * np.pi / places + 0.5 * ring
        points.append(centre + radius * np.column_stack([np.cos(angle), np.sin(angle)]))
        ring += 1
    return np.vstack(points)


def formation_goals(
    world: Host, creatures: Sequence[int], point: Sequence[float] | np.ndarray, shape: str
) -> np.ndarray:
    """A goal (n, 2) for each of `creatures` in `shape` around `point` (module doc)."""
    centre = np.asarray(point, dtype=np.float64)[:2]
    where = np.array([world.component(c, Transform).pos[:2] for c in creatures]).reshape(-1, 2)
    if len(creatures) == 1:
        return centre[None].copy()
    step = spacing([reach(world, c) for c in creatures])
    coming = centre - where.mean(axis=0)
    norm = float(np.linalg.norm(coming))
    facing = coming / norm if norm > 1e-9 else np.array([1.0, 0.0])
    ground = ground_of(world)
    wanted, made = len(creatures), np.zeros((0, 2))
    for extra in (0, len(creatures), 4 * len(creatures)):  # room for slots in obstacles
        made = slots(shape, wanted + extra, centre, step, facing)
        if ground.solids:
            points = np.column_stack([made, ground.surface(made)])
            made = made[ground.inside_solid(points, 0.5 * step) < 0]
        if len(made) >= wanted:
            break
    if len(made) < wanted:
        raise ValueError(f"no room for a {shape} of {wanted} creatures around {centre.tolist()}")
    cost = np.linalg.norm(where[:, None, :] - made[None, :, :], axis=2)
    rows, columns = linear_sum_assignment(cost)
    out = np.empty((wanted, 2))
    out[rows] = made[columns]
    return out
