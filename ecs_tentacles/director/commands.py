"""The director's edits, for the sandbox's undo stack (`ecs_tentacles.render.undo`).

Creatures are named, not numbered: an undone despawn builds the creature again (a new
entity, the same name), and later edits still find it. The physics is not rewound: an
undone despawn puts the creature back resting where it was (or, when something took
its place since, at the nearest free spot, as `spawn(on_overlap="move")`), an undone
move puts its joints back where they were when it was grabbed. Building creatures
again is whole or nothing: when one of them finds no free spot, none is built and the
edit raises `SpawnError` (the sandbox says so and keeps the edit to try again).

* `Spawned`: creatures placed (one, a scatter, a duplicate); undo despawns them.
* `Despawned`: creatures removed; undo builds them again where they were, with their
  goals and parameters at the time (`roster_save.entry_now`).
* `Moved`: a creature dragged or thrown; undo puts it back as it was grabbed.
* `ThreatDropped`: a danger (a threat) placed from the palette (`behaviour.placeable`);
  undo takes it away.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.behaviour import placeable
from ecs_tentacles.components import Creature
from ecs_tentacles.creatures.roster_save import entry_now
from ecs_tentacles.creatures.spawning import SpawnError, free_spot, place
from ecs_tentacles.scene.spec import CreatureSpec, as_spec

if TYPE_CHECKING:
    from ecs_tentacles.host import Host


def named(world: Host, name: str) -> int | None:
    """The entity of the creature called `name`, or None."""
    for entity, creature in world.query(Creature):
        if creature.name == name:
            return entity
    return None


def _despawn_named(world: Host, names: list[str]) -> None:
    for name in names:
        entity = named(world, name)
        if entity is not None:
            world.despawn(entity)


def _place_all(world: Host, entries: list[CreatureSpec]) -> None:
    """Build `entries` again, each where it was or at the nearest free spot; all or none."""
    built: list[int] = []
    try:
        for entry in entries:
            if named(world, entry["name"]) is None:  # its name is free again
                spot, blocker = free_spot(world, as_spec(copy.deepcopy(entry)))
                moved_to = None if blocker is None else tuple(spot["position"])
                built.append(place(world, spot, moved_to))
    except SpawnError:
        for entity in built:
            world.despawn(entity)
        raise


@dataclass
class Spawned:
    label: str
    entries: list[CreatureSpec]  # as they were placed (checked, names unique)

    @classmethod
    def of(cls, world: Host, label: str, entities: list[int]) -> Spawned:
        return cls(label, [copy.deepcopy(world.creature_specs[e]) for e in entities])

    def undo(self, world: Host) -> None:
        _despawn_named(world, [e["name"] for e in self.entries])

    def redo(self, world: Host) -> None:
        _place_all(world, self.entries)


@dataclass
class Despawned:
    label: str
    entries: list[CreatureSpec] = field(default_factory=list)  # as they were when removed

    @classmethod
    def remove(cls, world: Host, label: str, entities: list[int]) -> Despawned:
        """Despawn `entities`, keeping what undo needs to build them again."""
        made = cls(label, [as_spec(entry_now(world, e)) for e in entities])
        for entity in entities:
            world.despawn(entity)
        return made

    def undo(self, world: Host) -> None:
        _place_all(world, self.entries)

    def redo(self, world: Host) -> None:
        _despawn_named(world, [e["name"] for e in self.entries])


@dataclass
class Moved:
    label: str
    name: str
    before: np.ndarray  # its joints (qpos) when grabbed
    after: np.ndarray  # and when let go

    def _put(self, world: Host, qpos: np.ndarray) -> None:
        entity = named(world, self.name)
        if entity is None:
            return
        physics = world.physics
        index = physics.lod.index(entity)
        view = physics.views[index]
        physics.place_joints(index, qpos, np.zeros(view.model.nv))
        view.batch.sync(world.transforms)

    def undo(self, world: Host) -> None:
        self._put(world, self.before)

    def redo(self, world: Host) -> None:
        self._put(world, self.after)


@dataclass
class ThreatDropped:
    label: str
    name: str
    position: list[float]

    def undo(self, world: Host) -> None:
        source = placeable(world)
        if source is None or source.placed is None or source.remove is None:
            return  # the plugin that placed it is off now: nothing left to take away
        for entity, name in source.placed(world).items():
            if name == self.name:
                source.remove(world, entity)

    def redo(self, world: Host) -> None:
        source = placeable(world)
        if source is not None and source.drop is not None:
            source.drop(world, self.position, self.name)
