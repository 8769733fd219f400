"""Creatures on the screen: the names written over them (every creature's, or the
selection's, for the HUD), which creature is under a pixel (for clicks) and which
are inside a rectangle (for a rubber-band selection).

Reads the Transform store (mantle poses), `Creature` sizes and names, the camera.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.components import Creature
from ecs_tentacles.render.camera import ray_sphere

if TYPE_CHECKING:
    from ecs_tentacles.render.renderer import Renderer
    from ecs_tentacles.world import World

Label = tuple[str, float, float]  # text, pixel x, pixel y (pyglet's: from the bottom)
ABOVE = 1.8  # a label sits this many mantle heights (+ 5 cm) over the mantle's base
PICK_GROW = 1.25  # a click this far out from a mantle still picks it


def labels_over(world: World, renderer: Renderer, entities: Sequence[int]) -> list[Label]:
    """Labels above the mantles of creature `entities` (the drawn ones among them)."""
    wanted = set(entities)
    chosen = [(i, e) for i, e in enumerate(renderer.creature_entities) if e in wanted]
    if not chosen:
        return []
    creatures = [world.component(e, Creature) for _, e in chosen]
    tops = world.transforms.pos[renderer.mantle_rows[[i for i, _ in chosen]]].copy()
    tops[:, 2] += [c.mantle_height * ABOVE + 0.05 for c in creatures]
    pixels = renderer.camera.project(tops)
    return [(c.name, float(x), float(y)) for c, (x, y) in zip(creatures, pixels, strict=True)]


def creatures_in(
    world: World, renderer: Renderer, corner: Sequence[float], other: Sequence[float]
) -> list[int]:
    """The creatures whose mantle centre projects inside the pixel rectangle between
    `corner` and `other` (x, y; any two opposite corners), in drawing order."""
    entities = renderer.creature_entities
    if not entities:
        return []
    camera = renderer.camera
    centres = world.transforms.pos[renderer.mantle_rows]
    pixels = camera.project(centres)
    ahead = (centres - camera.eye) @ (camera.target - camera.eye) > 0  # not behind the eye
    low, high = np.minimum(corner, other), np.maximum(corner, other)
    inside = np.all((pixels >= low) & (pixels <= high), axis=1) & ahead
    return [entities[i] for i in np.flatnonzero(inside)]


def creature_at(world: World, renderer: Renderer, x: float, y: float) -> int | None:
    """The creature whose mantle is under pixel (x, y), nearest first, or None."""
    entities = renderer.creature_entities
    if not entities:
        return None
    origin, direction = renderer.camera.ray(x, y)
    creatures = [world.component(e, Creature) for e in entities]
    centres = world.transforms.pos[renderer.mantle_rows]
    radii = np.array([max(c.mantle_radius, c.mantle_height / 2) * PICK_GROW for c in creatures])
    hits = ray_sphere(origin, direction, centres, radii)
    best = int(np.argmin(hits))
    return entities[best] if np.isfinite(hits[best]) else None
