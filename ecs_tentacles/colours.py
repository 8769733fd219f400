"""Creature colours: the sandbox draws each creature in one, the exporters give each
creature a material of it (so a take opened in Blender looks like the sandbox).

    creature_colours(4)            # (4, 3) rgb in 0..1, as the sandbox shows them
    to_linear(creature_colours(4)) # the same colours as linear light (material factors)

The k-th creature gets the k-th colour: the scene's creatures in order, one spawned
later the next colour (the sandbox keeps each creature's colour while others come and
go; a take lists its creatures in the order they first appeared, so the k-th creature of
a take is the sandbox's k-th). Colours step round the hue wheel by the golden ratio from
a warm red, so neighbours in the list differ.

The values are display (sRGB-encoded) values: the sandbox writes them to the screen
as they are. Material colours in glTF (`baseColorFactor`) and USD (`diffuseColor`) are
linear, so the exporters write `to_linear(colour)`; textures (PNG) take the sRGB values.
"""

from __future__ import annotations

import colorsys

import numpy as np

FIRST_HUE = 0.02  # a warm red, octopus-like
HUE_STEP = 0.61803  # the golden ratio's fraction: successive hues far apart
SATURATION, VALUE = 0.65, 0.85
PALE = (0.95, 0.85, 0.80)  # the underside of a tentacle


def creature_colours(count: int) -> np.ndarray:
    """The first `count` creature colours (count, 3), display rgb in 0..1."""
    hues = (FIRST_HUE + HUE_STEP * np.arange(count)) % 1.0
    rgb = [colorsys.hsv_to_rgb(h, SATURATION, VALUE) for h in hues]
    return np.array(rgb, dtype=np.float64).reshape(-1, 3)


def to_linear(srgb: np.ndarray | tuple[float, ...]) -> np.ndarray:
    """sRGB-encoded values in 0..1 -> linear light (the IEC 61966-2-1 curve)."""
    c = np.clip(np.asarray(srgb, dtype=np.float64), 0.0, 1.0)
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)
