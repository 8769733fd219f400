"""The lod plugin's systems (`ecs_tentacles.clips`)."""
