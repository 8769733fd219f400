"""The clips plugin's systems (`ecs_tentacles.clips`)."""
