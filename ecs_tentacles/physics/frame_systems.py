"""The physics package's systems, declared here (their code is in `physics/systems/`).

physics (stage physics) steps MuJoCo; physics_sync and physics_health (stage sync)
copy the poses back and recover blow-ups. Every world runs them, whatever plugins
are on: `World.from_scene` schedules them first, owned by "core".
"""

from __future__ import annotations

from ecs_tentacles.system import System


def physics_systems() -> list[System]:
    """Fresh instances of the physics systems (physics, sync, health), in frame order."""
    from ecs_tentacles.physics.systems.physics import Physics
    from ecs_tentacles.physics.systems.physics_health import PhysicsHealth
    from ecs_tentacles.physics.systems.physics_sync import PhysicsSync

    systems: list[System] = [Physics(), PhysicsSync(), PhysicsHealth()]
    for system in systems:
        system.plugin = "core"
    return systems
