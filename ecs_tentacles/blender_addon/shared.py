"""The project's own modules the add-on runs as they are (numpy and the standard library
only): the skinned mesh (`ecs_tentacles.skin.mesh`) and the creatures' colours
(`ecs_tentacles.skin.colours`), so Blender shows the mesh and the colours the exporters
write, a take header's body plans (`ecs_tentacles.take.compact`) and the quaternion
product (`ecs_tentacles.numeric.hamilton`).

`ecs-tentacles blender-addon` puts those files into the add-on's zip as `skin_mesh.py`,
`skin_colours.py`, `take_compact.py` and `numeric_hamilton.py`; run from the package
itself (a development checkout, the tests) the add-on uses the package's modules.
"""

from __future__ import annotations

from importlib import import_module
from types import ModuleType

SHARED = {
    "skin_mesh": "ecs_tentacles.skin.mesh",
    "skin_colours": "ecs_tentacles.skin.colours",
    "take_compact": "ecs_tentacles.take.compact",
    "numeric_hamilton": "ecs_tentacles.numeric.hamilton",
}


def module(name: str) -> ModuleType:
    """A `SHARED` module by its name in the add-on: the copy in it, else the package's."""
    try:
        return import_module(f"{__package__}.{name}")
    except ModuleNotFoundError as missing:
        if missing.name != f"{__package__}.{name}":
            raise
        return import_module(SHARED[name])
