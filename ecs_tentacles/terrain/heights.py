"""A scene's `terrain.heightfield` -> a `Heightfield` (heights in metres on a grid).

Exactly one source: `noise` (OpenSimplex octaves, the same for the same seed),
`image` (a grayscale PNG next to the scene, 8 or 16 bit) or `heights` (rows along y
from -y/2). Problems come back as (JSON path, message) pairs; `heightfield` raises
`TerrainError` with the first one.
"""

from __future__ import annotations

import pathlib
from collections.abc import Mapping
from typing import Any

import numpy as np

from ecs_tentacles.ground import Heightfield

Problem = tuple[tuple[str | int, ...], str]
SOURCES = ("noise", "image", "heights")
HERE = ("terrain", "heightfield")
MAX_IMAGE_SIDE = 4096
MAX_IMAGE_BYTES = 64 << 20
MAX_RESOLUTION = 1024  # samples a side (the schema's maximum)


class TerrainError(ValueError):
    """A terrain that cannot be built: `path` is its JSON path, the message says why."""

    def __init__(self, path: tuple[str | int, ...], message: str):
        super().__init__(message)
        self.path = path


def source_problems(field: Mapping[str, Any]) -> list[Problem]:
    """What the schema cannot say: exactly one source, a rectangular `heights`."""
    given = [key for key in SOURCES if key in field]
    if len(given) != 1:
        have = ", ".join(given) if given else "none"
        return [(HERE, f"give exactly one of noise, image or heights (has: {have})")]
    if "heights" in field:
        rows = field["heights"]
        widths = {len(row) for row in rows}
        if len(widths) != 1:
            return [(HERE + ("heights",), f"rows must all be as long (lengths {sorted(widths)})")]
    return []


def heightfield(field: Mapping[str, Any], folder: pathlib.Path | None) -> Heightfield:
    """The heightfield `field` describes (schema-valid, defaults filled in)."""
    for path, message in source_problems(field):
        raise TerrainError(path, message)
    size = (float(field["size"][0]), float(field["size"][1]))
    if "heights" in field:
        heights = np.asarray(field["heights"], dtype=np.float64)
        bad = np.argwhere(~np.isfinite(heights))
        if len(bad):
            row, column = (int(v) for v in bad[0])
            raise TerrainError(HERE + ("heights", row, column), "must be a finite number")
    elif "image" in field:
        heights = _image_heights(field["image"], folder) * float(field.get("height", 1.0))
    else:
        heights = noise_heights(field.get("noise", {}), size, int(field.get("resolution", 128)))
        heights *= float(field.get("height", 1.0))
    return Heightfield(size, heights)


def noise_heights(
    noise: Mapping[str, Any], size: tuple[float, float], resolution: int
) -> np.ndarray:
    """(resolution, resolution) OpenSimplex heights from 0 to 1: octaves of halving size and
    weight, the same for the same seed."""
    import opensimplex

    generator = opensimplex.OpenSimplex(int(noise.get("seed", 0)))
    scale = float(noise.get("scale", 4.0))
    x = np.linspace(-0.5 * size[0], 0.5 * size[0], resolution)
    y = np.linspace(-0.5 * size[1], 0.5 * size[1], resolution)
    total = np.zeros((resolution, resolution))
    weight = 1.0
    for octave in range(int(noise.get("octaves", 3))):
        frequency = 2.0**octave / scale
        # noise2array(x, y) gives rows along y, columns along x; offsets decorrelate octaves
        total += weight * generator.noise2array(x * frequency + 17.3 * octave, y * frequency)
        weight *= 0.5
    low, high = total.min(), total.max()
    return (total - low) / (high - low) if high > low else np.zeros_like(total)


def _image_heights(name: str, folder: pathlib.Path | None) -> np.ndarray:
    """Heights 0..1 from a grayscale PNG next to the scene; row 0 of the array at -y."""
    from PIL import Image

    path = beside_scene(name, folder, HERE + ("image",))
    if path.stat().st_size > MAX_IMAGE_BYTES:
        raise TerrainError(HERE + ("image",), f"{name}: larger than {MAX_IMAGE_BYTES >> 20} MB")
    try:
        with Image.open(path) as image:
            if max(image.size) > MAX_IMAGE_SIDE or min(image.size) < 3:
                raise TerrainError(
                    HERE + ("image",),
                    f"{name}: {image.size[0]} x {image.size[1]} pixels; sides must be 3 to"
                    f" {MAX_IMAGE_SIDE}",
                )
            if image.mode not in ("L", "I;16", "I;16B", "I", "LA", "P", "RGB", "RGBA"):
                raise TerrainError(
                    HERE + ("image",), f"{name}: unsupported image mode {image.mode}"
                )
            wide = image.mode.startswith("I")
            pixels = np.asarray(image if wide else image.convert("L"), dtype=np.float64)
    except (OSError, SyntaxError) as error:  # PIL's "cannot identify image file"
        raise TerrainError(HERE + ("image",), f"{name}: not a readable PNG ({error})") from None
    top = 65535.0 if wide else 255.0
    return np.flipud(pixels) / top  # the picture's top row is +y


def beside_scene(
    name: str, folder: pathlib.Path | None, path: tuple[str | int, ...]
) -> pathlib.Path:
    """`name` as a file in the scene's folder (no path may lead out of it)."""
    if folder is None:
        raise TerrainError(path, f"{name}: a scene given as a dict has no folder to find it in")
    base = folder.resolve()
    found = (base / name).resolve()
    if not found.is_relative_to(base):
        raise TerrainError(path, f"{name}: must be a file in the scene's folder ({base})")
    if not found.is_file():
        raise TerrainError(path, f"{name}: no such file in the scene's folder ({base})")
    return found
