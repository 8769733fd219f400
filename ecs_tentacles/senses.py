"""What creatures sense beyond their own bodies: the dangers of the world, through a
registry (`ecs_tentacles.registry`) that plugins fill in `build(app)`.

    positions, owners = dangers(world)      # every danger now: (n, 3), (n,) entities

A `Dangers` entry is a `DangerSource`: `sense(world)` -> the positions (n, 3) of the
dangers it knows now and the creature entity each one is (-1: none; a creature never
fears itself); optionally `drop(world, position, name)` -> the entity of a danger
placed there from now on, `remove(world, entity)` and `placed(world)` -> {entity: name}
of the dangers placed so (the sandbox's palette and its undo). Behaviours that react to
danger (fur's emotion, the flee example) read `dangers(world)` and never name the
plugin that makes them; without any entry nothing frightens anyone.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.registry import Registry

if TYPE_CHECKING:
    from ecs_tentacles.host import Host


@dataclass(frozen=True)
class DangerSource:
    """Dangers one plugin knows, and (optionally) how to place and take them away."""

    sense: Callable[[Host], tuple[np.ndarray, np.ndarray]]
    drop: Callable[[Host, Sequence[float], str], int] | None = None
    remove: Callable[[Host, int], None] | None = None
    placed: Callable[[Host], dict[int, str]] | None = None


class Dangers(Registry[DangerSource]):
    """The world's sources of danger."""


def dangers(world: Host) -> tuple[np.ndarray, np.ndarray]:
    """Every danger now: positions (n, 3) and owner creature entities (n,; -1: none)."""
    found = [source.sense(world) for source in world.registry(Dangers)]
    if not found:
        return np.zeros((0, 3)), np.zeros(0, dtype=np.int64)
    positions = np.concatenate([np.asarray(p, dtype=np.float64).reshape(-1, 3) for p, _ in found])
    owners = np.concatenate([np.asarray(o, dtype=np.int64).reshape(-1) for _, o in found])
    return positions, owners


def placeable(world: Host) -> DangerSource | None:
    """The first source that can place dangers (`drop`), or None."""
    return next((s for s in world.registry(Dangers) if s.drop is not None), None)
