"""Locomotion's part in directing a crowd: what an undo puts back, what a save writes.

* `sandbox_state` / `sandbox_restore` (the sandbox's undo, `ecs_tentacles.render.undo`):
  every creature's goal path and run-time parameters (the columns the parameter table
  names, `locomotion.params.settable`), by creature name;
* `save_creature` (saving the roster as a scene, `ecs_tentacles.roster_save`): a
  creature's goals and its current parameters into its scene entry (tentacles that
  differ from the first as `overrides`).

Reads and writes `GoalBook` and the parameter columns of the locomotion and motor
stores.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from ecs_tentacles.components import Creature
from ecs_tentacles.locomotion.components import Goal
from ecs_tentacles.locomotion.goals import GoalBook
from ecs_tentacles.locomotion.params import ROWS, Locomotion, settable

if TYPE_CHECKING:
    from ecs_tentacles.host import Host


def _rows(world: Host, creature: int, kind: str) -> Any:
    row = world.component(creature, Creature).row
    if kind == "creature":
        return row
    first, count = int(world.creatures.first_tentacle[row]), int(world.creatures.tentacles[row])
    tentacles = np.arange(first, first + count)
    if kind == "tentacle":
        return tentacles
    starts, counts = world.tentacles.first_link[tentacles], world.tentacles.links[tentacles]
    return np.concatenate([np.arange(a, a + n) for a, n in zip(starts, counts, strict=True)])


def capture(world: Host, creature: int) -> dict[str, Any]:
    """The creature's run-time parameter columns, as stored."""
    per_tentacle, per_creature = settable()
    out = {}
    for p in {**per_tentacle, **per_creature}.values():
        values = getattr(world.stores[p.store], p.field)[_rows(world, creature, ROWS[p.store])]
        out[p.column] = np.array(values, copy=True)
    return out


def put(world: Host, creature: int, captured: dict[str, Any]) -> None:
    """Write back what `capture` returned."""
    per_tentacle, per_creature = settable()
    for p in {**per_tentacle, **per_creature}.values():
        if p.column in captured:
            rows = _rows(world, creature, ROWS[p.store])
            getattr(world.stores[p.store], p.field)[rows] = captured[p.column]


def goal_path(world: Host, creature: int) -> list[tuple[tuple[float, ...], float]]:
    goals = [world.component(g, Goal) for g in world.resource(GoalBook).path(creature)]
    return [(tuple(g.position.tolist()), float(g.radius)) for g in goals]


def sandbox_state(world: Host) -> dict[str, Any]:
    """Every creature's goal path and parameters, by creature name."""
    return {
        creature.name: (goal_path(world, entity), capture(world, entity))
        for entity, creature in world.query(Creature)
    }


def sandbox_restore(world: Host, state: dict[str, Any]) -> None:
    """Put back goal paths and parameters of the creatures still there (by name)."""
    book = world.resource(GoalBook)
    for entity, creature in world.query(Creature):
        if creature.name not in state:
            continue
        path, captured = state[creature.name]
        if goal_path(world, entity) != path:
            book.clear(entity)
            for position, radius in path:
                book.append(entity, list(position), radius)
        put(world, entity, captured)


def save_creature(world: Host, creature: int, entry: dict[str, Any]) -> None:
    """The creature's goals and current parameters into its scene entry."""
    entry["goals"] = [
        {"position": list(position), "radius": radius}
        for position, radius in goal_path(world, creature)
    ]
    api = world.resource(Locomotion)
    per_tentacle, per_creature = settable()
    first = api.get(creature, 0)
    for name, p in per_creature.items():
        shown = f"creature_{name}" if name in per_tentacle else name
        entry.setdefault(p.section, {})[p.key] = _scene_value(p, first[shown])
    count = api.tentacle_count(creature)
    values = [api.get(creature, k) for k in range(count)]
    tentacles = entry.setdefault("tentacles", {})
    overrides = {o["index"]: dict(o) for o in tentacles.get("overrides", [])}
    for name, p in per_tentacle.items():
        base = _scene_value(p, values[0][name])
        tentacles[p.key] = base
        for k in range(count):
            value = _scene_value(p, values[k][name])
            if value != base:
                overrides.setdefault(k, {"index": k})[p.key] = value
            elif k in overrides:
                overrides[k].pop(p.key, None)
    kept = [overrides[k] for k in sorted(overrides) if len(overrides[k]) > 1]
    tentacles["overrides"] = kept


def _scene_value(p: Any, value: Any) -> Any:
    if p.choices or isinstance(value, int):
        return value
    return round(float(value) / p.factor, 12)
