"""Locomotion's part in directing a crowd: what an undo puts back, what a save writes.

* `DirectedStates.capture` / `sandbox_restore` (the sandbox's undo,
  `ecs_tentacles.render.undo`): every creature's goal path and run-time parameters (the
  columns the parameter table names, `locomotion.params.settable`), put back by name;
* `save_creature` (saving the roster as a scene, `ecs_tentacles.creatures.roster_save`): a
  creature's goals and its current parameters into its scene entry (tentacles that
  differ from the first as `overrides`).

Reads and writes `GoalBook` and the parameter columns of the locomotion and motor
stores.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, SupportsFloat

import numpy as np

from ecs_tentacles.components import Creature
from ecs_tentacles.locomotion.components import Goal
from ecs_tentacles.locomotion.goals import GoalBook
from ecs_tentacles.locomotion.params import ROWS, Locomotion, settable

if TYPE_CHECKING:
    from ecs_tentacles.host import Host
    from ecs_tentacles.scene.parameters import Parameter


LAYOUT = {"creatures": ("first_tentacle", "tentacles"), "tentacles": ("first_link", "links")}


def goal_path(world: Host, creature: int) -> list[tuple[tuple[float, ...], float]]:
    goals = [world.component(g, Goal) for g in world.resource(GoalBook).path(creature)]
    return [(tuple(g.position.tolist()), float(g.radius)) for g in goals]


def _parameters() -> list[Parameter]:
    per_tentacle, per_creature = settable()
    return list({**per_tentacle, **per_creature}.values())


@dataclass(eq=False)
class Directed:
    """Every creature's goals and run-time parameters at one moment (an undo memento):
    the parameter columns copied whole, the rows each creature had then, the goal paths
    by name. Two are equal when nothing a user directs differs."""

    names: list[str]  # by creature row
    rows: dict[str, np.ndarray]  # where each creature's tentacles and links were
    columns: dict[str, np.ndarray]  # parameter column ("store.field") -> its values
    version: int  # the goal book's, when `goals` were read
    goals: dict[str, list[tuple[tuple[float, ...], float]]]

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Directed):
            return NotImplemented
        return (
            self.names == other.names
            and (self.version == other.version or self.goals == other.goals)
            and all(np.array_equal(a, other.columns[k]) for k, a in self.columns.items())
        )

    def span(self, kind: str, row: int) -> np.ndarray:
        """The rows of `kind` ("creature", "tentacle", "link") creature row `row` had."""
        if kind == "creature":
            return np.array([row])
        first, count = (self.rows[k][row] for k in LAYOUT["creatures"])
        tentacles = np.arange(first, first + count)
        if kind == "tentacle":
            return tentacles
        starts, counts = (self.rows[k][tentacles] for k in LAYOUT["tentacles"])
        return np.concatenate([np.arange(a, a + n) for a, n in zip(starts, counts, strict=True)])


class DirectedStates:
    """Makes `Directed` mementos; the goal paths are read again only when the goal book
    changed (a slider drag captures every frame: whole-column copies, no per-creature
    Python)."""

    def __init__(self) -> None:
        self._goals: tuple[int, dict[str, list[tuple[tuple[float, ...], float]]]] | None = None

    def capture(self, world: Host) -> Directed:
        book = world.resource(GoalBook)
        entities = world.creatures.entity.tolist()
        names = [world.creature_name(e) for e in entities]
        if self._goals is None or self._goals[0] != book.version:
            paths = {n: goal_path(world, e) for n, e in zip(names, entities, strict=True)}
            self._goals = (book.version, {n: p for n, p in paths.items() if p})
        rows = {k: getattr(world.stores[s], k).copy() for s, ks in LAYOUT.items() for k in ks}
        columns = {p.column: getattr(world.stores[p.store], p.field).copy() for p in _parameters()}
        return Directed(names, rows, columns, *self._goals)


def sandbox_restore(world: Host, state: Directed) -> None:
    """Put back goal paths and parameters of the creatures still there (by name)."""
    book = world.resource(GoalBook)
    now = DirectedStates().capture(world)
    was = {name: row for row, name in enumerate(state.names)}
    for entity, creature in world.query(Creature):
        old = was.get(creature.name)
        if old is None:
            continue
        path = state.goals.get(creature.name, [])
        if now.goals.get(creature.name, []) != path:
            book.clear(entity)
            for position, radius in path:
                book.append(entity, list(position), radius)
        for p in _parameters():
            kind = ROWS[p.store]
            column = getattr(world.stores[p.store], p.field)
            column[now.span(kind, creature.row)] = state.columns[p.column][state.span(kind, old)]


def save_creature(world: Host, creature: int, entry: dict[str, object]) -> None:
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
        _section(entry, p.section)[p.key] = _scene_value(p, first[shown])
    count = api.tentacle_count(creature)
    values = [api.get(creature, k) for k in range(count)]
    tentacles = _section(entry, "tentacles")
    listed = tentacles.get("overrides", [])
    if not isinstance(listed, list):
        raise TypeError(f"{entry.get('name')}: its tentacles' overrides are a list")
    overrides = {o["index"]: dict(o) for o in listed}
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


def _section(entry: dict[str, object], key: str) -> dict[str, object]:
    """The entry's object `key` (made empty if it has none)."""
    section = entry.setdefault(key, {})
    if not isinstance(section, dict):
        raise TypeError(f"{entry.get('name')}: its {key} is an object, not {section!r}")
    return section


def _scene_value(p: Parameter, value: object) -> object:
    if p.choices or isinstance(value, int):
        return value
    if not isinstance(value, SupportsFloat):
        raise TypeError(f"{p.api}: {value!r} is not a number")
    return round(float(value) / p.factor, 12)
