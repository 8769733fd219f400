"""The record feature's system (`ecs_tentacles.record`): record (stage output)."""
