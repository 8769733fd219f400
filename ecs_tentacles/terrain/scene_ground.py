"""A scene's `terrain` entry -> the core `Ground` (the terrain plugin's and editor's).

Reads the heightfield source and the obstacles' files from the scene's folder; a
missing or bad one is a `SceneError` naming the field.
"""

from __future__ import annotations

import pathlib

from ecs_tentacles.ground import FLAT, Ground
from ecs_tentacles.scene.errors import SceneError
from ecs_tentacles.scene.validate import format_path
from ecs_tentacles.terrain.ground import TerrainGround
from ecs_tentacles.terrain.heights import TerrainError, heightfield
from ecs_tentacles.terrain.solids import solids
from ecs_tentacles.terrain.terrain_spec import TerrainSpec


def build_ground(terrain: TerrainSpec, folder: pathlib.Path | None) -> Ground:
    """The `Ground` a scene's `terrain` describes (FLAT for `{}`); SceneError names the
    field when a file is missing or bad."""
    if (
        not terrain.get("heightfield")
        and not terrain.get("obstacles")
        and "friction" not in terrain
    ):
        return FLAT
    try:
        field = heightfield(terrain["heightfield"], folder) if terrain.get("heightfield") else None
        shapes = solids(terrain.get("obstacles", []), folder, field)
    except TerrainError as error:
        raise SceneError([f"{format_path(error.path)}: {error}"]) from None
    friction = terrain.get("friction")
    return TerrainGround(field, shapes, None if friction is None else float(friction))
