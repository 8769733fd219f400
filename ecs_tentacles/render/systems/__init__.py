"""The render feature's system (`ecs_tentacles.render.plugin`): render (stage output)."""
