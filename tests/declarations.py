"""Run systems with only what they declare: undeclared columns unreadable and read-only.

`declared_only(world, system)` swaps every store's column table for one that refuses
columns the system neither reads nor writes (`UndeclaredRead`), and makes every column
it does not declare in `writes` read-only (numpy `flags.writeable = False`: a write
raises `ValueError: assignment destination is read-only`). A declaration names a
whole store (`"locomotion.tentacles"`) or one column (`"fur.controls.drive_lift"`),
against `world.stores`; names that are not stores (`"goals"`, `"physics"`) are
resources and are not checked here; anything else must resolve.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterable, Iterator
from typing import Any

from ecs_tentacles.system import System
from ecs_tentacles.world import World

# declared names that are (attributes of) resources or engine parts, not store columns:
# "fur.curves" is FurData's output buffer, "goals" the GoalBook
RESOURCES = {"goals", "physics", "action_queues", "fur"}


class UndeclaredRead(KeyError):
    """A system read a store column it does not declare."""


class _Guarded(dict[str, Any]):
    """A store's column table that refuses columns a system did not declare."""

    def __init__(self, arrays: dict[str, Any], allowed: set[str], where: str):
        super().__init__(arrays)
        self.allowed, self.where = allowed, where

    def __getitem__(self, field: str) -> Any:
        if field not in self.allowed:
            raise UndeclaredRead(f"{self.where}.{field}")
        return super().__getitem__(field)


def columns(world: World, names: Iterable[str]) -> tuple[set[tuple[str, str]], list[str]]:
    """((store, field) pairs the declared `names` cover, names that resolve to nothing)."""
    found: set[tuple[str, str]] = set()
    unknown: list[str] = []
    for name in names:
        if name in world.stores:
            found |= {(name, f.name) for f in world.stores[name].fields()}
            continue
        store, _, field = name.rpartition(".")
        if store in world.stores and any(f.name == field for f in world.stores[store].fields()):
            found.add((store, field))
        elif name.partition(".")[0] not in RESOURCES:
            unknown.append(name)
    return found, unknown


@contextlib.contextmanager
def declared_only(world: World, system: System) -> Iterator[None]:
    """While inside, `system` can read what it declares and write what it declares writing."""
    writes, _ = columns(world, system.writes)
    reads, _ = columns(world, system.reads)
    if system.calls_hooks:  # what the plugins' hooks read, it reads
        reads |= columns(world, [r for p in world.plugins for r in p.hook_reads])[0]
    readable = reads | writes
    saved = {}
    for name, store in world.stores.items():
        arrays = store._arrays
        saved[name] = arrays
        allowed = {field for (s, field) in readable if s == name}
        store.cache_views = False  # every read goes through the guarded table
        store._arrays = _Guarded(arrays, allowed, name)
        for field, array in arrays.items():
            array.flags.writeable = (name, field) in writes
    try:
        yield
    finally:
        for store in world.stores.values():
            arrays = dict(store._arrays)  # a store that grew inside has its new arrays here
            store._arrays = arrays
            for array in arrays.values():
                array.flags.writeable = True
            store.cache_views = True


def step_declared(world: World, frames: int) -> None:
    """`world.step(frames)`, each system run inside `declared_only` (failures name it)."""
    world.activate()
    dt = world.settings.dt
    for _ in range(frames):
        for system in world.schedule:
            try:
                with declared_only(world, system):
                    system.process(world, dt)
            except UndeclaredRead as read:
                raise AssertionError(
                    f"system {system.name!r} read {read.args[0]} without declaring it in reads"
                ) from read
            except ValueError as error:
                if "read-only" not in str(error):
                    raise
                raise AssertionError(
                    f"system {system.name!r} wrote a column it does not declare in writes"
                    f" at frame {world.frame}: {error}"
                ) from error
        world.frame += 1
