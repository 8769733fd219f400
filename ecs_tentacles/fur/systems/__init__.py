"""The fur feature's systems (`ecs_tentacles.fur`): emotion, rig (stage animate)."""
