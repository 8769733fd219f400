"""Creatures joining and leaving a running physics (`World.spawn` / `despawn`).

`add_creature` gives a just-built creature a row in the batch of its morphology
(compiling a model only for a new morphology) and a place in every per-creature table
(roster, contact proxies, health, sleep, level of detail); `remove_creature` takes one
out after its store rows were removed, renumbering the store rows the batches hold;
`view_of(creature)` finds a creature's physics (the index is made again after each).
Nothing of any other creature changes: each is its own row of state. `Membership` is
part of `PhysicsBackend` (its parts are declared here for the type checker).
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from typing import TYPE_CHECKING

import mujoco
import numpy as np

from ecs_tentacles.components import Creature, Transform
from ecs_tentacles.physics.batch import Batch
from ecs_tentacles.physics.model import build_spec, model_layout
from ecs_tentacles.physics.reduced import ReducedModel
from ecs_tentacles.physics.reduced_body import chains, reduced_spec
from ecs_tentacles.physics.tiers import FULL, reduced_substeps
from ecs_tentacles.physics.view import CreatureView, CreatureViews

if TYPE_CHECKING:
    from ecs_tentacles.physics.health import HealthCheck
    from ecs_tentacles.physics.host import PhysicsHost
    from ecs_tentacles.physics.lod import LevelOfDetail
    from ecs_tentacles.physics.proxies import ContactProxies
    from ecs_tentacles.physics.roster import Roster
    from ecs_tentacles.physics.sleep import Sleep

S = mujoco.mjtState


def compile_models(
    world: PhysicsHost, creature: Creature
) -> tuple[mujoco.MjModel, Callable[[], ReducedModel]]:
    """The compiled model of `creature`'s morphology, and how to compile its reduced one
    (the REDUCED level of detail, `physics.reduced`) when first needed.

    The reduced model is compiled later from the spec built now: by then `creature` may
    have been despawned (the batch outlives its first member), so nothing of the world
    is read again.
    """
    model = build_spec(world, creature).compile()
    reduced_dt = world.settings.dt / reduced_substeps(world.settings.substeps)
    spec = reduced_spec(world, creature, reduced_dt)
    tentacles = chains(world, creature)

    def reduced() -> ReducedModel:
        return ReducedModel(model, spec.compile(), tentacles)

    return model, reduced


class Membership:
    """Adding and removing creatures (module docstring)."""

    roster: Roster
    batches: list[Batch]
    threads: int
    time: float
    compiles: int
    proxies: ContactProxies
    health: HealthCheck
    sleep: Sleep
    lod: LevelOfDetail
    views: CreatureViews
    view_of_creature_row: np.ndarray

    def _index_views(self, creature_rows: int) -> None:
        """Each creature's `CreatureView`, and where to find it by creature-store row
        (after every join and leave)."""
        roster = self.roster
        self.views = CreatureViews(roster)
        self.view_of_creature_row = np.full(creature_rows, -1, dtype=np.int64)
        self.view_of_creature_row[roster.creature_row] = np.arange(len(roster))

    def view_of(self, creature: Creature) -> CreatureView:
        """The physics of `creature` (its batch, row and ids)."""
        return self.views[int(self.view_of_creature_row[creature.row])]

    # -- names kept for scripts written before views had their name -------------------
    def group_of(self, creature: Creature) -> CreatureView:
        """Deprecated: `view_of` (a creature's physics is a view, not a group)."""
        warnings.warn(
            "physics.group_of is deprecated: use physics.view_of", DeprecationWarning, stacklevel=2
        )
        return self.view_of(creature)

    @property
    def groups(self) -> CreatureViews:
        """Deprecated: `views` (each creature's `CreatureView`)."""
        warnings.warn(
            "physics.groups is deprecated: use physics.views", DeprecationWarning, stacklevel=2
        )
        return self.views

    def add_creature(self, world: PhysicsHost, entity: int) -> int:
        """Give the just-built creature `entity` its physics, at its built pose: a row in
        the batch of its morphology (a model is compiled only for a new morphology).
        Nothing of any other creature changes. Returns its roster index."""
        creature, transform = world.component(entity, Creature), world.component(entity, Transform)
        layout = model_layout(world, creature, transform)
        roster = self.roster
        index = len(roster)
        batch = next((b for b in self.batches if b.key == layout.key), None)
        if batch is None:
            model, reduced = compile_models(world, creature)
            batch = Batch(len(self.batches), model, [layout], reduced)
            batch.members[:] = index
            self.batches.append(batch)
            self.compiles += 1
            row = 0
        else:
            row = batch.append(layout, index)
        batch.prepare(FULL, self.threads)
        batch.place(row, np.array(transform.pos), np.array(transform.quat))
        batch.part(S.mjSTATE_TIME, row)[:] = self.time
        roster.append(entity, creature.row, batch, row)
        self.proxies.append(batch, row)
        poses = world.transforms.pos[batch.body_rows[row]]
        self.health.grow(batch.index, batch.state[row], poses, self.proxies)
        self.sleep.grow(batch.index, 2 * batch.model.nu)
        self.lod.grow()
        self._index_views(len(world.creatures))
        return index

    def remove_creature(
        self, world: PhysicsHost, entity: int, moved: dict[str, np.ndarray]
    ) -> None:
        """Take creature `entity` out (its stores' rows are already removed; `moved`:
        every old row's new row by store name, as `ArrayStore.remove` answered). Its
        batch keeps its model for the next creature of that shape."""
        roster = self.roster
        index = self.lod.index(entity)
        batch, row = roster.locate(index)
        roster.remove(index)
        for each in self.batches:
            each.renumber(moved)
        if "creatures" in moved:
            roster.creature_row = moved["creatures"][roster.creature_row]
        rows = len(world.transforms)
        if "transforms" in moved:
            self.proxies.remove(index, moved["transforms"])
        else:
            self.proxies.reindex()
        kept = moved["transforms"] >= 0 if "transforms" in moved else np.ones(rows, dtype=bool)
        self.health.remove(index, batch.index, row, kept, self.proxies)
        self.sleep.remove(index, batch.index, row)
        self.lod.remove(index)
        self._index_views(len(world.creatures))
