"""The physics systems, scheduled by the physics package (`ecs_tentacles.physics`):
physics (stage physics), physics_sync, physics_health (stage sync)."""
