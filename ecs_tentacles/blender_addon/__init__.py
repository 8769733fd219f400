"""ecs_tentacles take importer: a Blender add-on (an extension of Blender 4.2 and later).

File > Import > ecs_tentacles take (.npz), or from a script:

    bpy.ops.import_scene.ecs_tentacles_take(filepath="crowd.npz")

opens a take as armatures and skinned meshes, one per creature, sharing armature and
mesh data per body plan; creatures replaying a gait clip share one action per clip and
kind through NLA strips offset in time; creatures simulated at some frame have an action
of their own (`build` says how). Install it with `ecs-tentacles blender-addon --install`
(or `blender --command extension install-file -r user_default -e` on the zip that
`ecs-tentacles blender-addon --out` writes).

Runs in Blender's own Python (numpy and the standard library): it does not import
ecs_tentacles; `shared` names the two of the project's files the zip carries.
This module imports no bpy itself, so the reading parts (`reader`, `motion`) load
outside Blender too.
"""

from __future__ import annotations


def register() -> None:
    """Blender calls this when the add-on is enabled."""
    from . import operator

    operator.register()


def unregister() -> None:
    """Blender calls this when the add-on is disabled."""
    from . import operator

    operator.unregister()
