"""ecs_tentacles: tentacled creatures on an entity-component-system.

Scene file -> entities (components whose numbers live in contiguous arrays) ->
systems in a named order -> MuJoCo physics -> Transform store -> renderer / exporters.
"""

__version__ = "0.1.0"
