"""Terrain: a heightfield and static obstacles instead of the flat plane (plugin `terrain`).

The scene's `terrain` becomes the world's core `ecs_tentacles.ground.Ground`
(`plugin.TerrainPlugin`): heights from noise, an image or an array (`heights`), obstacles
from primitives or mesh files (`solids`), ready-made terrains for generated crowds
(`presets`).
"""
