"""The MuJoCo backend: model building from entities, stepping and syncing.

`backend` (the batches, stepped in parallel; `state()` / `set_state()`), `view` (one
creature's physics: `physics.view_of(creature)`), `model`, `proxies`, `health`,
`sleep`, `registries`; `host` is what the physics needs of a world (a Protocol: nothing
here imports `ecs_tentacles.world`); `frame_systems` declares the physics systems every
world runs (their code is in `physics/systems/`).
"""
