"""The renderer's link instance table: every link's transform row, size and colour.

A creature's table (`creature_links`: its links' rows relative to its mantle's, their
radii and lengths, their place along their tentacle) is read from its components once
and kept by the renderer: a creature's body rows stay together and in order whatever
is removed around them, so its mantle row alone places it. `link_instances` joins the
tables of the creatures drawn into one instance array (tinted from each creature's
colour, paler toward the tips) in one numpy pass.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.components import Creature, Link, Tentacle, Transform
from ecs_tentacles.render.gpu import INSTANCE_FLOATS

if TYPE_CHECKING:
    from ecs_tentacles.host import Host


@dataclass(frozen=True)
class CreatureStatic:
    """One creature's links: Transform rows relative to its mantle's, (radius, length),
    index along the tentacle and the tentacle's link count."""

    rows: np.ndarray
    sizes: np.ndarray
    index: np.ndarray
    chain: np.ndarray


@dataclass(frozen=True)
class LinkInstances:
    """Every drawn link: its Transform row, its instance (pose filled per frame), the
    index of its creature among those drawn and its index along its tentacle."""

    rows: np.ndarray
    instances: np.ndarray
    creature: np.ndarray
    index: np.ndarray


def creature_links(world: Host, creature: Creature, mantle_row: int) -> CreatureStatic:
    """`creature`'s link table, its rows relative to `mantle_row`."""
    rows, sizes, index, length = [], [], [], []
    for tentacle_entity in creature.tentacles:
        tentacle = world.component(tentacle_entity, Tentacle)
        for link_entity in tentacle.links:
            link = world.component(link_entity, Link)
            rows.append(world.component(link_entity, Transform).row - mantle_row)
            sizes.append((link.radius, link.length))
            index.append(link.index)
            length.append(len(tentacle.links))
    return CreatureStatic(
        np.array(rows, dtype=np.int64),
        np.array(sizes, dtype=np.float64).reshape(-1, 2),
        np.array(index, dtype=np.int64),
        np.array(length, dtype=np.int64),
    )


def link_instances(
    tables: list[CreatureStatic], mantle_rows: np.ndarray, colours: np.ndarray
) -> LinkInstances:
    """The links of creatures `tables` (mantles at `mantle_rows`, `colours` rgb each)."""
    counts = np.array([len(t.rows) for t in tables], dtype=np.int64)
    creature = np.repeat(np.arange(len(tables)), counts)
    if len(creature):
        rel = np.concatenate([t.rows for t in tables])
        sizes = np.concatenate([t.sizes for t in tables])
        index = np.concatenate([t.index for t in tables])
        chain = np.concatenate([t.chain for t in tables])
    else:
        rel, sizes = np.zeros(0, np.int64), np.zeros((0, 2))
        index, chain = np.zeros(0, np.int64), np.ones(0, np.int64)
    instances = np.zeros((len(rel), INSTANCE_FLOATS), np.float32)
    shade = (1.0 - 0.35 * index / np.maximum(chain - 1, 1))[:, None]
    instances[:, 7:10] = sizes[:, :1]
    instances[:, 10] = sizes[:, 1] / 2
    instances[:, 11:14] = np.clip(colours[creature] * shade + 0.08 * (1 - shade), 0, 1)
    instances[:, 14] = 1.0
    return LinkInstances(rel + mantle_rows[creature], instances, creature, index)
