"""A scene's `terrain` key as TypedDicts: `TerrainSpec`, `HeightfieldSpec`, `ObstacleSpec`.

What `terrain.schema.json` (beside this file) says, as types mypy checks every read of
the terrain against; the terrain plugin narrows the scene it is handed to these where
it reads them (the validator has checked the key against the schema by then).
Reads nothing, writes nothing.
"""

from __future__ import annotations

from typing import Required, TypedDict


class NoiseSpec(TypedDict, total=False):
    """`heightfield.noise`: OpenSimplex octaves (`terrain.heights.noise_heights`)."""

    seed: int
    scale: float  # m across the largest bumps
    octaves: int


class HeightfieldSpec(TypedDict, total=False):
    """`terrain.heightfield`: heights on a grid from one of noise, image or heights."""

    size: Required[list[float]]  # m, x and y
    resolution: int  # samples a side (noise)
    height: float  # m from the lowest point to the highest (noise), or white's (image)
    noise: NoiseSpec
    image: str  # a grayscale PNG next to the scene
    heights: list[list[float]]  # m, rows along y


class ShapeKeys(TypedDict, total=False):
    """An obstacle's keys besides its shape and position (which a shape needs:
    `terrain.solids.NEEDS`)."""

    on_ground: bool
    rotation_deg: list[float]  # x, y, z
    size: list[float]  # m (box, rock)
    radius: float  # m (cylinder, sphere)
    height: float  # m (cylinder)
    file: str  # a mesh next to the scene
    scale: float  # a mesh's
    seed: int  # a rock's


class ObstacleSpec(ShapeKeys, total=False):
    """One of `terrain.obstacles`."""

    shape: Required[str]  # box, cylinder, sphere, mesh or rock
    position: Required[list[float]]  # m, x, y, z


class TerrainSpec(TypedDict, total=False):
    """A scene's `terrain`."""

    heightfield: HeightfieldSpec
    obstacles: list[ObstacleSpec]
    friction: float
