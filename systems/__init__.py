"""Built-in systems, one per file; installed as `ecs_tentacles.systems`.

The frame runs them in this order (each file's docstring says what it reads and
writes; `World.schedule.names` shows the resolved order, user systems included):

1. physics       motor targets, gains and sucker switches -> MuJoCo; mj_step x substeps
2. physics_sync  MuJoCo body poses -> Transform store
"""

from __future__ import annotations

from ecs_tentacles.systems.physics import Physics
from ecs_tentacles.systems.physics_sync import PhysicsSync

from ecs_tentacles.system import System

__all__ = ["Physics", "PhysicsSync", "builtin_systems"]


def builtin_systems() -> list[System]:
    """Fresh instances of the built-in systems, in frame order."""
    return [Physics(), PhysicsSync()]
