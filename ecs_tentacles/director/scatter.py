"""Scatter: many copies of one creature in a disc, none overlapping, seeded.

    entities = scatter(world, preset.creature(), centre=(4, 2), radius=3.0, count=20, seed=7)

Spots are drawn uniformly in the disc (a random heading each) from a generator seeded
with `seed`, and kept when the creature's reach circle (mantle plus longest tentacle,
`GAP` more) is clear of every creature there (their reach spheres now) and of every
spot kept before, no obstacle is within its reach, and on a heightfield the whole reach
circle lies on it (a creature past its edge drops off it). The same world, entry and seed
give the same spots. Fewer than `count` come back when the disc is full (say so). The
entry is checked once (`World.spawn`'s rules); every copy then costs only its build
(`spawning.place`): 100 creatures in well under a second.
"""

from __future__ import annotations

import copy
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.creatures.spawning import creature_entry, place, unique_name
from ecs_tentacles.ground import ground_of
from ecs_tentacles.scene.construction import creature_layout
from ecs_tentacles.scene.spec import as_spec

if TYPE_CHECKING:
    from ecs_tentacles.host import Host

GAP = 0.1  # metres between two creatures' reach circles
TRIES = 40  # candidate spots drawn per creature wanted


def reach_of(entry: Mapping[str, object]) -> float:
    """How far a creature built from `entry` reaches from its mantle's axis (metres)."""
    layout = creature_layout(as_spec({**entry, "position": [0.0, 0.0]}))
    _, ends, radii = layout.capsules()
    return float(np.max(np.linalg.norm(ends[:, :2], axis=1)) + radii.max())


def spots(
    world: Host,
    entry: Mapping[str, object],
    centre: Sequence[float] | np.ndarray,
    radius: float,
    count: int,
    seed: int,
) -> np.ndarray:
    """Up to `count` free spots (k, 3): x, y, heading in degrees (module docstring)."""
    if count < 0 or not radius >= 0:
        raise ValueError(f"scatter: count must be >= 0 and radius >= 0, got {count}, {radius}")
    rng = np.random.default_rng(seed)
    reach = reach_of(entry)
    tries = max(1, TRIES * count)
    distance = radius * np.sqrt(rng.random(tries))
    angle = rng.uniform(0.0, 2.0 * np.pi, tries)
    heading = rng.uniform(-180.0, 180.0, tries)
    middle = np.asarray(centre, dtype=np.float64)[:2]
    candidates = middle + distance[:, None] * np.column_stack([np.cos(angle), np.sin(angle)])
    clear = _clear_of_creatures(world, candidates, reach) & _clear_of_obstacles(
        world, candidates, reach
    )
    clear &= _on_the_heightfield(world, candidates, reach)
    kept: list[int] = []
    for i in np.flatnonzero(clear).tolist():
        if len(kept) == count:
            break
        if kept:
            gap = np.linalg.norm(candidates[kept] - candidates[i], axis=1)
            if (gap < 2.0 * reach + GAP).any():
                continue
        kept.append(i)
    return np.column_stack([candidates[kept], heading[kept]]).reshape(-1, 3)


def _clear_of_creatures(world: Host, points: np.ndarray, reach: float) -> np.ndarray:
    physics = world.physics
    if not len(physics):
        return np.ones(len(points), dtype=bool)
    _, _, centres, reaches = physics.proxies.sense(world.transforms)
    middle = points.mean(axis=0)
    spread = float(np.linalg.norm(points - middle, axis=1).max())
    near = np.linalg.norm(centres[:, :2] - middle, axis=1) < spread + reaches + reach + GAP
    gap = np.linalg.norm(points[:, None, :] - centres[None, near, :2], axis=2)
    return np.asarray((gap >= reaches[None, near] + reach + GAP).all(axis=1))


def _on_the_heightfield(world: Host, points: np.ndarray, reach: float) -> np.ndarray:
    """(n,) whose reach circle lies inside the heightfield (all of them without one)."""
    extent = ground_of(world).extent
    if extent is None:
        return np.ones(len(points), dtype=bool)
    half = extent - reach
    return np.asarray((np.abs(points) <= half).all(axis=1))


def _clear_of_obstacles(world: Host, points: np.ndarray, reach: float) -> np.ndarray:
    ground = ground_of(world)
    if not ground.has_obstacles:
        return np.ones(len(points), dtype=bool)
    raised = np.column_stack([points, ground.height(points)])
    return np.asarray(ground.inside_solid(raised, reach) < 0)


def scatter(
    world: Host,
    spec: Mapping[str, object],
    centre: Sequence[float] | np.ndarray,
    radius: float,
    count: int,
    seed: int = 0,
) -> list[int]:
    """Spawn up to `count` copies of creature `spec` at `spots`; their entities."""
    entry = creature_entry(world, spec)  # checked once: SpawnError names the field
    made = []
    for x, y, heading in spots(world, entry, centre, radius, count, seed).tolist():
        copy_of: dict[str, object] = copy.deepcopy(dict(entry))
        copy_of["name"] = unique_name(world, entry["name"])
        copy_of["position"] = [x, y]
        copy_of["heading_deg"] = heading
        copy_of["goals"] = []
        made.append(place(world, as_spec(copy_of)))
    return made
