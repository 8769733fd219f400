"""Record: the run captured into a take (`ecs-tentacles bake` adds the plugin).

- `plugin`: the `record` plugin; its system is `ecs_tentacles.record.systems.record`,
  which fills the generic recorder (`ecs_tentacles.export.recording`).
"""
