"""The herding game's systems (`ecs_tentacles.herding`): `predator` (stage animate, in
the `DANGERS_MOVED` phase) and `referee` (stage output)."""
