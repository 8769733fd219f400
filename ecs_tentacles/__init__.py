"""ecs_tentacles: tentacled creatures on an entity-component-system.

Scene file -> entities (components whose numbers live in contiguous arrays) ->
systems in a named order -> MuJoCo physics -> Transform store -> renderer / exporters.
"""

__version__ = "0.1.0"

from ecs_tentacles.processes import no_library_search as _no_library_search

_no_library_search()  # before anything imports mujoco (see ecs_tentacles.processes)
