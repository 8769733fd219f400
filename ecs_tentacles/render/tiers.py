"""Tier markers: a small sphere above each creature's mantle, coloured by its physics tier.

Reads the level of detail's tiers (`world.lod.roster.tier`, `physics.tiers`), the
renderer's interpolated poses and creature list, and the camera's metres per pixel;
returns `Marker`s (one batch per tier) for the render plugin's `Spheres` entry when
the HUD's "show tiers" box is ticked. The HUD's tier counts use the same `COLOURS`,
so the counts are the legend. One numpy pass per frame, whatever the crowd's size.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.components import Creature
from ecs_tentacles.physics.tiers import NAMES
from ecs_tentacles.render.registries import Marker

if TYPE_CHECKING:
    from ecs_tentacles.render.renderer import Renderer

# tier name -> rgba: full green, reduced orange (not the attached suckers' yellow),
# kinematic blue; fully saturated, so they stand out from the creatures' softer skins
COLOURS: dict[str, tuple[float, float, float, float]] = {
    "full": (0.1, 0.85, 0.2, 1.0),
    "reduced": (1.0, 0.45, 0.0, 1.0),
    "kinematic": (0.15, 0.4, 1.0, 1.0),
}
TEXT_SHADE = 0.7  # the HUD writes the counts in darker shades (legible on its light panel)


def text_colour(name: str) -> tuple[float, float, float, float]:
    """The HUD's colour for tier `name`'s count: its marker colour, darker."""
    r, g, b, a = COLOURS[name]
    return r * TEXT_SHADE, g * TEXT_SHADE, b * TEXT_SHADE, a


SIZE_OF_MANTLE = 0.45  # a marker's radius, as a share of the mean mantle radius
MIN_PIXELS = 4.0  # but never smaller than this on screen (crowds seen from afar)


def tier_markers(renderer: Renderer) -> list[Marker]:
    """A sphere above every creature's mantle in its tier's colour (one `Marker` per tier)."""
    entities = np.asarray(renderer.creature_entities, dtype=np.int64)
    roster = renderer.world.lod.roster
    if not len(entities) or not len(roster):
        return []
    index = np.searchsorted(roster.entity, entities).clip(0, len(roster) - 1)
    if not (roster.entity[index] == entities).all():  # creatures the physics does not know
        return []
    heights, radius = _mantles(renderer)
    view = renderer.render_view
    tops = view.pos[renderer.mantle_rows].copy()
    size = max(SIZE_OF_MANTLE * radius, MIN_PIXELS * view.pixel)
    tops[:, 2] += heights + 2.0 * size
    tier = roster.tier[index]
    markers = []
    for code, name in enumerate(NAMES):
        chosen = tier == code
        if chosen.any():
            markers.append(Marker(tops[chosen], (size, size, size), COLOURS[name]))
    return markers


@dataclass(frozen=True)
class _Mantles:
    """What `_mantles` keeps in the renderer's state, and for which world."""

    world: object
    heights: np.ndarray
    radius: float


def _mantles(renderer: Renderer) -> tuple[np.ndarray, float]:
    """Each creature's mantle height and the mean mantle radius (kept per renderer world)."""
    cached = renderer.state.get("tier_mantles")
    if isinstance(cached, _Mantles) and cached.world is renderer.world:
        return cached.heights, cached.radius
    creatures = [renderer.world.component(e, Creature) for e in renderer.creature_entities]
    heights = np.array([c.mantle_height for c in creatures])
    radius = float(np.mean([c.mantle_radius for c in creatures]))
    renderer.state["tier_mantles"] = _Mantles(renderer.world, heights, radius)
    return heights, radius
