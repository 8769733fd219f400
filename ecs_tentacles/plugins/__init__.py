"""The built-in features, each a `Plugin` (`ecs_tentacles.plugin`), each file one plugin.

    locomotion  goals, gait, action queues: goals, tentacle_selection, action_queue,
                motor_targets (stages decide, act)
    suckers     attach and release at the tips: suckers (stage act)
    threats     marked threats and their paths: threats (stage animate)
    fur         fur, feathers and emotion: emotion, rig (stage animate)
    record      a take of the run, added by `bake`: record (stage output)
    render      the sandbox's drawing, added by `play`: render (stage output)

The first four are on unless a scene turns them off (`"plugins": {"fur": false}`);
record and render are added by the commands that need them (`world.add_plugin`).
Core (World, Schedule, physics, the creature body) imports none of them.
"""
