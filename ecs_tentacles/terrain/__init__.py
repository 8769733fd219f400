"""Terrain: a heightfield and static obstacles instead of the flat plane (plugin `terrain`).

The scene's `terrain` becomes the world's ground (`plugin.TerrainPlugin`): a
`TerrainGround` (`ground`: every query core's `ecs_tentacles.ground.Ground` protocol
asks, the MuJoCo geoms, the meshes in `ground_meshes`) of a `Heightfield`
(`heightfield`) and `Solid`s (`shapes`); heights from noise, an image or an array
(`heights`), obstacles from primitives or mesh files (`solids`), ready-made terrains
for generated crowds (`presets`).
"""
