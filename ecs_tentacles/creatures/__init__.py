"""The world's creatures: built from a scene, coming and going while it runs, saved back.

Modules: `loading` (a scene -> a running world: `World.from_scene` delegates there),
`body` (scene data -> a creature's entities and store rows, posed by the construction
rules of `ecs_tentacles.scene.construction`), `spawning` (`World.spawn` and
`World.despawn`; plugins and systems hear of it through
`ecs_tentacles.roster_change`) and `roster_save` (a running world written back as a
scene).
"""
