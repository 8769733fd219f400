"""A scene's `terrain.heightfield` -> a `Heightfield` (heights in metres on a grid).

Exactly one source: `noise` (OpenSimplex octaves, the same for the same seed),
`image` (a grayscale PNG next to the scene, 8 or 16 bit) or `heights` (rows along y
from -y/2). Problems come back as (JSON path, message) pairs; `heightfield` raises
`TerrainError` with the first one.

An image is bounded as the other sources are: at most `MAX_RESOLUTION` (1024) pixels a
side, like `resolution` and `heights` (a larger one is refused, not resampled: scale it
down with any image tool, and see what you get); its size is read from the PNG's header
before anything is decoded, so a decompression bomb costs nothing. Only PNG files are
read (by their signature, whatever the name), and heights are clamped to [0, height].
A 1024 x 1024 heightfield takes 8 MB here and 4 MB in each compiled physics model
(each body plan's, and each stepping thread's copy of it).
"""

from __future__ import annotations

import io
import pathlib

import numpy as np

from ecs_tentacles.plugin import Problem
from ecs_tentacles.terrain.heightfield import Heightfield
from ecs_tentacles.terrain.terrain_spec import HeightfieldSpec, NoiseSpec
from ecs_tentacles.untrusted.files import TooLarge, Unfit, read_regular

SOURCES = ("noise", "image", "heights")
HERE = ("terrain", "heightfield")
MAX_RESOLUTION = 1024  # samples a side (the schema's maximum)
MAX_IMAGE_SIDE = MAX_RESOLUTION  # pixels a side: an image is no bigger than `resolution`
MAX_IMAGE_BYTES = 64 << 20
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


class TerrainError(ValueError):
    """A terrain that cannot be built: `path` is its JSON path, the message says why."""

    def __init__(self, path: tuple[str | int, ...], message: str):
        super().__init__(message)
        self.path = path


def source_problems(field: HeightfieldSpec) -> list[Problem]:
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


def heightfield(field: HeightfieldSpec, folder: pathlib.Path | None) -> Heightfield:
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


def noise_heights(noise: NoiseSpec, size: tuple[float, float], resolution: int) -> np.ndarray:
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


def png_size(head: bytes) -> tuple[int, int] | None:
    """(width, height) from a PNG file's first 24 bytes; None if it is not a PNG."""
    if len(head) < 24 or not head.startswith(PNG_SIGNATURE) or head[12:16] != b"IHDR":
        return None
    return int.from_bytes(head[16:20], "big"), int.from_bytes(head[20:24], "big")


def _image_heights(name: str, folder: pathlib.Path | None) -> np.ndarray:
    """Heights 0..1 from a grayscale PNG next to the scene; row 0 of the array at -y."""
    from PIL import Image

    here = HERE + ("image",)
    path = beside_scene(name, folder, here)
    data = read_found(path, name, here, MAX_IMAGE_BYTES)
    sides = png_size(data[:24])
    if sides is None:
        raise TerrainError(here, f"{name}: not a PNG image (its first bytes are not a PNG's)")
    if max(sides) > MAX_IMAGE_SIDE or min(sides) < 3:
        raise TerrainError(
            here,
            f"{name}: {sides[0]} x {sides[1]} pixels; sides must be 3 to {MAX_IMAGE_SIDE}"
            + (" (as resolution's): scale it down" if max(sides) > MAX_IMAGE_SIDE else ""),
        )
    try:
        with Image.open(io.BytesIO(data), formats=["PNG"]) as image:
            if image.size != sides:  # the header read above and Pillow's disagree
                raise TerrainError(here, f"{name}: not a readable PNG (its header is damaged)")
            if image.mode not in ("1", "L", "I;16", "I;16B", "I", "LA", "P", "RGB", "RGBA"):
                raise TerrainError(here, f"{name}: unsupported image mode {image.mode}")
            wide = image.mode.startswith("I")
            pixels = np.asarray(image if wide else image.convert("L"), dtype=np.float64)
    except (OSError, SyntaxError, ValueError, Image.DecompressionBombError) as error:
        reason = " ".join(str(error).split())[:120] or "damaged"
        raise TerrainError(here, f"{name}: not a readable PNG ({reason})") from None
    top = 65535.0 if wide else 255.0
    return np.clip(np.flipud(pixels) / top, 0.0, 1.0)  # the picture's top row is +y


def beside_scene(
    name: str, folder: pathlib.Path | None, path: tuple[str | int, ...]
) -> pathlib.Path:
    """`name` as a file in the scene's folder (no path may lead out of it)."""
    if folder is None:
        raise TerrainError(path, f"{name}: a scene given as a dict has no folder to find it in")
    if "\x00" in name:
        raise TerrainError(path, f"{name!r}: a file name cannot hold a NUL character")
    base = folder.resolve()
    try:
        found = (base / name).resolve()
    except (OSError, RuntimeError) as error:  # a symlink loop, a name too long
        raise TerrainError(path, f"{name}: cannot find it ({error})") from None
    if not found.is_relative_to(base):
        raise TerrainError(path, f"{name}: must be a file in the scene's folder ({base})")
    if not found.is_file():
        raise TerrainError(path, f"{name}: no such file in the scene's folder ({base})")
    return found


def read_found(path: pathlib.Path, name: str, here: tuple[str | int, ...], limit: int) -> bytes:
    """The bytes of file `path` (scene name `name`, at JSON path `here`), read once, as it
    is now: what `beside_scene` found may have been swapped since, so it is checked as
    read (a regular file of at most `limit` bytes)."""
    try:
        return read_regular(path, limit)
    except TooLarge:
        raise TerrainError(here, f"{name}: larger than {limit >> 20} MB") from None
    except Unfit as unfit:
        raise TerrainError(here, f"{name}: cannot read it ({unfit.reason})") from None
    except OSError as error:
        raise TerrainError(here, f"{name}: cannot read it ({error.strerror})") from None
