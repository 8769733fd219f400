"""The threats feature's system (`ecs_tentacles.threats`): threats (stage animate)."""
