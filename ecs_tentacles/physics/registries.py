"""The physics layer's registries (`ecs_tentacles.registry`), filled in plugins' `build(app)`.

- `MotionWants`: `entry(world)` -> which creatures a plugin wants to move now (bool per
  CreatureStore row) or None for none; asked every frame before the step, or-ed: a
  creature some plugin wants to move never falls asleep (`physics.sleep`). Locomotion:
  creatures with a goal; the director: the grabbed creature.
- `StaticGeometry` (in `physics.model`, which calls it): the static geoms in every
  creature's model.
- `TravelTargets`: `entry(world)` -> where creatures are heading, (CreatureStore rows,
  2) x, y metres, nan where nowhere, or None; the level of detail moves kinematic
  creatures toward the first answer that is not nan (`ecs_tentacles.clips.replay`).

Entries answer with whole-array math (no per-creature loop); their arrays are only read.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.registry import Registry

if TYPE_CHECKING:
    from ecs_tentacles.host import Host


class MotionWants(Registry[Callable[["Host"], np.ndarray | None]]):
    """Creatures plugins want to move now (they stay awake)."""


class TravelTargets(Registry[Callable[["Host"], np.ndarray | None]]):
    """Where creatures are heading, for the creatures the level of detail replays."""
