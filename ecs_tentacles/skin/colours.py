"""Creature colours: the sandbox draws each creature in one, the exporters give each
creature a material of it (so a take opened in Blender looks like the sandbox).

    creature_colour(look, "natural")   # (3,) rgb in 0..1: THE choice, sandbox and exports
    look_in_world(world, entity, k)    # a creature's `Look` from a world (k: its place)
    look_in_take(header, k)            # the k-th creature's `Look` from a take's header
    creature_colours(4)                # (4, 3) the debug palette's first four colours
    to_linear(creature_colours(4))     # the same colours as linear light (material factors)

Two palettes (`PALETTES`). "natural" (the default): muted, skin-like hues (rose, coral,
terracotta, tan, mauve), one per species (the body: tentacle and link counts, mantle
size) and varied a little per creature (its name), so a crowd of one species reads as
one kind of animal and a mixed one as several. "debug": the bright colours below, a
different one per creature, to tell creatures apart at a glance.

In the debug palette the k-th creature gets the k-th colour: the scene's creatures in
order, one spawned later the next colour (the sandbox keeps each creature's colour while
others come and go; a take lists its creatures in the order they first appeared, so the
k-th creature of a take is the sandbox's k-th). Colours step round the hue wheel by the
golden ratio from a warm red, so neighbours in the list differ.

The values are display (sRGB-encoded) values: the sandbox writes them to the screen
as they are. Material colours in glTF (`baseColorFactor`) and USD (`diffuseColor`) are
linear, so the exporters write `to_linear(colour)`; textures (PNG) take the sRGB values.
"""

from __future__ import annotations

import colorsys
import hashlib
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

# numpy and the standard library only when it runs: the Blender add-on runs this file as
# it is (`ecs_tentacles.blender_addon.shared`)
if TYPE_CHECKING:
    from collections.abc import Mapping

    from ecs_tentacles.host import Host

FIRST_HUE = 0.02  # a warm red, octopus-like
HUE_STEP = 0.61803  # the golden ratio's fraction: successive hues far apart
SATURATION, VALUE = 0.65, 0.85
PALE = (0.95, 0.85, 0.80)  # the underside of a tentacle
PALETTES = ("natural", "debug")
# natural: (hue, saturation, value) of the species' tones, and how far a creature strays
NATURAL_TONES = (
    (0.015, 0.42, 0.78),  # rose
    (0.045, 0.50, 0.80),  # coral
    (0.060, 0.55, 0.66),  # terracotta
    (0.085, 0.40, 0.74),  # tan
    (0.960, 0.30, 0.66),  # mauve
    (0.030, 0.30, 0.62),  # dusky brown-pink
    (0.000, 0.52, 0.70),  # brick red
    (0.075, 0.28, 0.82),  # pale sand-pink
)
NATURAL_SPREAD = (0.012, 0.05, 0.05)  # +- hue, saturation, value per creature


@dataclass(frozen=True)
class Look:
    """What a creature's colour is chosen from: its `name`, its place `index` among the
    creatures (the k-th: the debug palette) and its `body` (the species: tentacle count,
    links per tentacle, mantle radius in mm)."""

    name: str
    index: int
    body: tuple[int, ...]


def creature_colour(creature: Look, palette: str = "natural") -> np.ndarray:
    """The colour (3,) display rgb in 0..1 of `creature` in `palette` ("natural" or
    "debug"); the one function the sandbox and the exporters choose colours with."""
    if palette == "debug":
        return np.asarray(creature_colours(creature.index + 1)[creature.index])
    if palette != "natural":
        raise ValueError(f"palette must be one of {', '.join(PALETTES)}, got {palette!r}")
    # the species' place round the ring of tones, between two neighbours
    place = _unit_hashes(repr(creature.body), 1)[0] * len(NATURAL_TONES)
    k, blend = int(place), place - int(place)
    first, second = (
        np.array(NATURAL_TONES[k]),
        np.array(NATURAL_TONES[(k + 1) % len(NATURAL_TONES)]),
    )
    if abs(second[0] - first[0]) > 0.5:  # round the red end of the wheel, not across it
        second[0] += 1.0 if second[0] < first[0] else -1.0
    hue, saturation, value = first + blend * (second - first)
    jitter = 2.0 * _unit_hashes(creature.name, 3) - 1.0  # this creature's own, in [-1, 1)
    hue = (hue + NATURAL_SPREAD[0] * jitter[0]) % 1.0
    saturation = float(np.clip(saturation + NATURAL_SPREAD[1] * jitter[1], 0.0, 1.0))
    value = float(np.clip(value + NATURAL_SPREAD[2] * jitter[2], 0.0, 1.0))
    return np.array(colorsys.hsv_to_rgb(hue, saturation, value), dtype=np.float64)


def _unit_hashes(text: str, count: int) -> np.ndarray:
    """`count` numbers in [0, 1) from `text`, the same in every run and on every machine."""
    digest = hashlib.blake2b(text.encode(), digest_size=2 * count).digest()
    return np.frombuffer(digest, dtype=">u2").astype(np.float64) / 65536.0


def body_key(mantle_radius: float, links: list[int]) -> tuple[int, ...]:
    """A species' key: tentacle count, each tentacle's link count, mantle radius (mm)."""
    return (len(links), *links, round(1000.0 * mantle_radius))


def look_in_world(world: Host, entity: int, index: int) -> Look:
    """Creature `entity`'s `Look` (`index`: its place among the creatures)."""
    from ecs_tentacles.components import Creature, Tentacle

    creature = world.component(entity, Creature)
    links = [len(world.component(t, Tentacle).links) for t in creature.tentacles]
    return Look(str(creature.name), index, body_key(creature.mantle_radius, links))


def look_in_take(header: Mapping[str, object], index: int) -> Look:
    """The `Look` of a take's `index`-th creature (its header's `creatures[index]`)."""
    creatures, bodies = header["creatures"], header["bodies"]
    assert isinstance(creatures, list) and isinstance(bodies, list)  # as `take.header` checks
    entry = creatures[index]
    radius = float(bodies[entry["mantle"]]["radius"])
    links = [len(chain) for chain in entry["tentacles"]]
    return Look(str(entry["name"]), index, body_key(radius, links))


def creature_colours(count: int) -> np.ndarray:
    """The debug palette's first `count` colours (count, 3), display rgb in 0..1."""
    hues = (FIRST_HUE + HUE_STEP * np.arange(count)) % 1.0
    rgb = [colorsys.hsv_to_rgb(h, SATURATION, VALUE) for h in hues]
    return np.array(rgb, dtype=np.float64).reshape(-1, 3)


def to_linear(srgb: np.ndarray | tuple[float, ...]) -> np.ndarray:
    """sRGB-encoded values in 0..1 -> linear light (the IEC 61966-2-1 curve)."""
    c = np.clip(np.asarray(srgb, dtype=np.float64), 0.0, 1.0)
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)
