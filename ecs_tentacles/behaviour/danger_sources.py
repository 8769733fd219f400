"""The dangers creatures fear: the `Dangers` registry (entries: `DangerSource`) that
plugins fill in `build(app)` (threats, the herding predator), and what behaviours ask of
it (`dangers(world)`: every danger now; `placeable(world)`: who can place one). Reads
the world's `Dangers` entries; writes nothing itself.
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
