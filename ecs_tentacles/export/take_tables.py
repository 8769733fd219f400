"""A take's body and sucker tables: which store rows are which bodies and suckers.

`TakeTables` is the layout side of `ecs_tentacles.export.recording.TakeRecorder` (its
base): it reads a world's creatures, tentacles, links, transforms and suckers once when
the recording starts (and again for a creature spawned while it runs) and writes the
take header's `creatures`, `bodies` and `suckers` tables, in take order (creature by
creature, mantle then links tentacle by tentacle; then the suckers), with the store
rows the recorder gathers each frame from (`_rows`, `_sucker_rows`, `_span`).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Literal

import numpy as np

from ecs_tentacles.components import Creature, Link, Tentacle, Transform
from ecs_tentacles.numeric.rows import ordinals, run_slice

if TYPE_CHECKING:
    from ecs_tentacles.take.header_entries import HeaderBody, HeaderCreature, HeaderSucker
    from ecs_tentacles.world import World


class TakeTables:
    """Body and sucker tables in take order, and the store rows behind them."""

    _span: slice | None  # the bodies as one run of store rows, or None

    def _layout(self, world: World) -> None:
        """Body and sucker tables in take order: creature by creature, mantle then links."""
        self._creatures: list[HeaderCreature] = []
        self._bodies: list[HeaderBody] = []
        self._suckers: list[HeaderSucker] = []
        self.creature_index: dict[int, int] = {}  # creature entity -> its index in the take
        self._rows = np.zeros(0, dtype=np.int64)  # take body -> Transform row (-1: gone)
        self._sucker_rows = np.zeros(0, dtype=np.int64)  # take sucker -> Sucker row
        by_row = sorted(world.query(Creature), key=lambda item: item[1].row)
        self._add_creatures(world, by_row)

    def _add_creatures(self, world: World, creatures: Sequence[tuple[int, Creature]]) -> None:
        """Append creatures to the take's tables: each one's mantle, then its links
        tentacle by tentacle; then their suckers, creature by creature, in store order."""
        first = len(self._bodies)
        rows: list[int] = []
        for entity, creature in creatures:
            rows += self._add_bodies(world, entity, creature)
        added = np.asarray(rows, dtype=np.int64)
        self._rows = np.concatenate([self._rows, added])
        # the bodies as one run of store rows, or None (what a roster change leaves is
        # gathered row by row: `_changes`)
        self._span = run_slice(self._rows)
        self._add_suckers(world, added, first)

    def _add_bodies(self, world: World, entity: int, creature: Creature) -> list[int]:
        """Append one creature's bodies to the take's tables; their Transform rows."""
        index = self.creature_index[entity] = len(self._creatures)
        world.kept_names.add(name := creature.name)  # a later spawn of it gets a suffix
        first = len(self._bodies)
        rows = [world.component(entity, Transform).row]
        entry: HeaderCreature = {"name": name, "mantle": first, "tentacles": []}
        self._bodies.append(_body(f"{name}/mantle", index, "cylinder", "Z", creature))
        for tentacle_entity in creature.tentacles:
            tentacle = world.component(tentacle_entity, Tentacle)
            chain = []
            for link_entity in tentacle.links:
                link = world.component(link_entity, Link)
                chain.append(first + len(rows))
                rows.append(world.component(link_entity, Transform).row)
                body = f"{name}/tentacles/t{tentacle.index}/link{link.index}"
                self._bodies.append(_body(body, index, "capsule", "X", link))
            entry["tentacles"].append(chain)
        self._creatures.append(entry)
        return rows

    def _add_suckers(self, world: World, rows: np.ndarray, first: int) -> None:
        """Append the suckers on the take's bodies `first...` (at Transform `rows`):
        creature by creature, each creature's in store order, named by their body."""
        suckers = world.suckers
        body_of_row = np.full(len(world.transforms), -1, dtype=np.int64)
        body_of_row[rows] = np.arange(first, first + len(rows))
        carrier = body_of_row[suckers.link_row]
        mine = np.flatnonzero(carrier >= 0)
        owner = np.array([body["creature"] for body in self._bodies[first:]], dtype=np.int64)
        mine = mine[np.argsort(owner[carrier[mine] - first], kind="stable")]
        carriers = carrier[mine]
        number = ordinals(carriers)  # each sucker's place among its body's
        offsets = suckers.offset[mine].tolist()
        for body, n, offset in zip(carriers.tolist(), number.tolist(), offsets, strict=True):
            name = f"{self._bodies[body]['name']}/sucker{n}"
            self._suckers.append({"name": name, "body": body, "offset": offset})
        self._sucker_rows = np.concatenate([self._sucker_rows, mine])


def _body(
    name: str,
    creature: int,
    shape: Literal["cylinder", "capsule"],
    axis: Literal["X", "Z"],
    part: Creature | Link,
) -> HeaderBody:
    if isinstance(part, Creature):
        radius, length = part.mantle_radius, part.mantle_height
    else:
        radius, length = part.radius, part.length
    return {
        "name": name,
        "creature": creature,
        "shape": shape,
        "axis": axis,
        "radius": float(radius),
        "length": float(length),
    }
