"""World snapshots: the whole simulation state, restored to continue bit-identically.

    snap = world.snapshot()       # cheap copies, no pickling of MuJoCo objects
    world.step(300)
    world.restore(snap)           # back to where it was; stepping again repeats exactly

A snapshot holds every store's live rows, the physics' own state
(`PhysicsBackend.state()`: each group's integration state and run-time flags, the
health check's memory, the sleep counters, the physics clock), what each plugin saves
(`Plugin.snapshot`: goal paths and action queues, fur stores, threats), the state
systems declare (`System.state_attributes`), the frame counter and the random
generator, and the roster (every creature's entry, by entity). It lives in memory and
belongs to the world it came from.

Creatures spawned since the snapshot are despawned by a restore (the world goes back
to the roster it had). A creature despawned since cannot come back with its old
entity: such a restore is refused, and nothing changes. A restore is whole or nothing:
the events it emits (`creature_despawned`) reach their handlers after it is complete
(`World.restore` holds them), so a handler that spawns spawns into the restored world.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Protocol

import numpy as np

from ecs_tentacles.components import Creature

if TYPE_CHECKING:
    from ecs_tentacles.host import Host
    from ecs_tentacles.physics.backend import PhysicsState
    from ecs_tentacles.store import ArrayStore

    class Restorable(Host, Protocol):
        """A world whose clock a restore sets (`ecs_tentacles.world.World` is one)."""

        frame: int


@dataclass
class Snapshot:
    """Everything `World.restore` needs; opaque to callers."""

    frame: int
    rng: dict[str, object]
    stores: dict[str, tuple[int, dict[str, np.ndarray]]]
    physics: PhysicsState
    plugins: dict[str, object]
    systems: dict[str, dict[str, object]] = field(default_factory=dict)
    roster: dict[int, str] = field(default_factory=dict)  # creature entity -> name
    origin: str = ""  # the world it was taken of (its esper context)


def _stores(world: Restorable) -> dict[str, ArrayStore]:
    return world.stores  # the core's and every plugin's, by name


def take(world: Restorable) -> Snapshot:
    """Copy the world's state (see the module docstring)."""
    return Snapshot(
        frame=world.frame,
        rng=dict(copy.deepcopy(world.rng.bit_generator.state)),
        stores={name: store.copy_rows() for name, store in _stores(world).items()},
        physics=world.physics.state(),
        plugins={plugin.key: plugin.snapshot(world) for plugin in world.plugins},
        systems={
            system.name: {a: copy.deepcopy(getattr(system, a)) for a in system.state_attributes}
            for system in world.schedule
            if system.state_attributes
        },
        roster={entity: creature.name for entity, creature in _creatures(world)},
        origin=getattr(world, "context", ""),
    )


def _creatures(world: Restorable) -> list[tuple[int, Creature]]:
    return sorted(world.query(Creature))


class SnapshotMismatch(ValueError):
    """A snapshot that does not fit this world; the world was left as it was."""


def mismatch(world: Restorable, snapshot: Snapshot) -> str | None:
    """Why `snapshot` does not fit `world` (one line), or None: checked before a restore
    changes anything."""
    for name, store in _stores(world).items():
        if name in snapshot.stores:
            problem = store.rows_problem(snapshot.stores[name])
            if problem:
                return f"store {name!r}: the snapshot has {problem}"
    problem = world.physics.state_problem(snapshot.physics)
    return f"physics: the snapshot has {problem}" if problem else None


def restore(world: Restorable, snapshot: Snapshot) -> None:
    """Put the world back in `snapshot`'s state.

    Raises SnapshotMismatch (and changes nothing) when the snapshot is of another world
    whose stores or physics do not have the same shape, or names a creature despawned
    since. Creatures spawned since are despawned."""
    alive = {entity for entity, _ in _creatures(world)}
    same = snapshot.origin == getattr(world, "context", "")  # else: shapes must fit as they are
    gone = [name for entity, name in snapshot.roster.items() if entity not in alive]
    if same and gone:
        raise SnapshotMismatch(
            f"cannot restore this snapshot: creature {gone[0]!r} was despawned since"
            " (spawn it again from world.creature_specs, or restore a later snapshot)"
        )
    if same:
        for entity in sorted(alive - set(snapshot.roster), reverse=True):
            world.despawn(entity)
    problem = mismatch(world, snapshot)
    if problem:
        raise SnapshotMismatch(f"cannot restore a snapshot of another world: {problem}")
    world.frame = snapshot.frame
    world.rng.bit_generator.state = copy.deepcopy(snapshot.rng)
    for name, store in _stores(world).items():
        if name in snapshot.stores:  # a plugin added since has nothing to go back to
            store.put_rows(snapshot.stores[name])
    world.physics.set_state(snapshot.physics)
    for plugin in world.plugins:
        if plugin.key in snapshot.plugins:  # a plugin added since has nothing to go back to
            plugin.restore(world, snapshot.plugins[plugin.key])
    for system in world.schedule:
        for attribute, value in snapshot.systems.get(system.name, {}).items():
            setattr(system, attribute, copy.deepcopy(value))
