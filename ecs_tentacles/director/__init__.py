"""The crowd director: the sandbox's tools to place, remove, move and send creatures.

A feature package like any other (its plugin, `director.plugin`, is added by the
sandbox: entry-point group `ecs_tentacles.plugins.sandbox`). Its parts:

* `palette`: the creatures (and threats) that can be placed: the bundled scenes',
  the creature generator's species, creatures exported from the creator;
* `scatter`: seeded spots for N creatures in a disc, none overlapping;
* `commands`: the undo stack (spawn, despawn, move, goals, parameters);
* `grab`: the spring that drags and throws a creature (as MuJoCo's `simulate` does);
* `save`: the roster, goals and settings written back as a scene;
* `panel`: the HUD section and the mouse and keys that use all of them.
"""
