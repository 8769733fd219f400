"""The director's system (`ecs_tentacles.director`): grab (stage act)."""
