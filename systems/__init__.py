"""Built-in systems, one per file; installed as `ecs_tentacles.systems`.

The frame runs them in this order (each file's docstring says what it reads and
writes; `World.schedule.names` shows the resolved order, user systems included):

1. goals               mantle inside its current goal's radius -> goal removed, next one current
2. tentacle_selection  who drives, push or pull (cyclic or coordinated gait); idle without a goal
3. action_queue        action timers advance; finished actions give way to the next
4. motor_targets       action poses + travelling waves -> joint targets; writhing -> gains
5. suckers             attach at the ground on command; release on command, stretch or reach
6. physics             motor targets, gains, sucker switches, contact proxies -> every physics
                       group; mj_step x substeps on the thread pool
7. physics_sync        MuJoCo body poses -> Transform store
8. physics_health      blow-ups found per creature; that creature restored to its last good state
9. emotion             threats near -> fear/aggression level -> fur controls' lift and random
10. rig                fur guides posed from mantle poses and controls (tracks, dynamic blend)
"""

from __future__ import annotations

from ecs_tentacles.systems.action_queue import ActionQueueSystem
from ecs_tentacles.systems.emotion import EmotionSystem
from ecs_tentacles.systems.goals import Goals
from ecs_tentacles.systems.motor_targets import MotorTargets
from ecs_tentacles.systems.physics import Physics
from ecs_tentacles.systems.physics_health import PhysicsHealth
from ecs_tentacles.systems.physics_sync import PhysicsSync
from ecs_tentacles.systems.rig import Rig
from ecs_tentacles.systems.suckers import Suckers
from ecs_tentacles.systems.tentacle_selection import TentacleSelection

from ecs_tentacles.system import System

__all__ = [
    "ActionQueueSystem",
    "EmotionSystem",
    "Goals",
    "MotorTargets",
    "Physics",
    "PhysicsHealth",
    "PhysicsSync",
    "Rig",
    "Suckers",
    "TentacleSelection",
    "builtin_systems",
]


def builtin_systems() -> list[System]:
    """Fresh instances of the built-in systems, in frame order."""
    return [
        Goals(),
        TentacleSelection(),
        ActionQueueSystem(),
        MotorTargets(),
        Suckers(),
        Physics(),
        PhysicsSync(),
        PhysicsHealth(),
        EmotionSystem(),
        Rig(),
    ]
