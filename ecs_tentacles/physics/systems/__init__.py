"""The physics systems, declared by the physics package
(`ecs_tentacles.physics.frame_systems.physics_systems`): physics (stage physics),
physics_sync, physics_health (stage sync)."""
