"""Creature construction rules of the tentacle thesis (IV.A), translated to z-up.

* The mantle is a cylinder with its height along +z.
* Tentacle k of N lies along +x rotated by 360 deg * k / N about +z (counter-clockwise
  seen from above), its base on the outside edge of the mantle's base.
* Link i of n has scale 1 - (i / (n - 1)) * (1 - end_scale); a one-link tentacle is
  the first link alone, at scale 1. Its length and radius are the first link's times
  its scale.
* The first link's centre lies mantle radius + 1/2 link length along the axis; each
  child's centre lies 1/2 (parent length + child length) beyond its parent's.

These functions are pure: numbers in, numpy arrays out.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


def link_scales(links: int, end_scale: float) -> np.ndarray:
    """Scale factor of each of `links` links, from 1 at the base to `end_scale` at the tip."""
    if links < 1:
        raise ValueError(f"a tentacle needs at least one link, got {links}")
    if not 0.0 < end_scale <= 1.0:
        raise ValueError(f"end_scale must be in (0, 1], got {end_scale}")
    if links == 1:
        return np.ones(1)
    i = np.arange(links, dtype=np.float64)
    return 1.0 - (i / (links - 1)) * (1.0 - end_scale)


def tentacle_angles(count: int) -> np.ndarray:
    """Base angle (radians about +z) of each of `count` tentacles, counter-clockwise from +x."""
    if count < 1:
        raise ValueError(f"a creature needs at least one tentacle, got {count}")
    return 2.0 * np.pi * np.arange(count) / count


def tentacle_axes(count: int) -> np.ndarray:
    """Unit axis (count, 3) of each tentacle in the creature frame."""
    angles = tentacle_angles(count)
    return np.stack([np.cos(angles), np.sin(angles), np.zeros(count)], axis=1)


@dataclass(frozen=True)
class TentacleShape:
    """Per-link numbers of one tentacle; `centres` are distances along its axis."""

    scales: np.ndarray
    lengths: np.ndarray
    radii: np.ndarray
    centres: np.ndarray


def tentacle_shape(
    mantle_radius: float, link_length: float, link_radius: float, links: int, end_scale: float
) -> TentacleShape:
    """Lengths, radii and centre distances of a tentacle's links by the thesis's rules."""
    scales = link_scales(links, end_scale)
    lengths = link_length * scales
    radii = link_radius * scales
    centres = np.empty(links)
    centres[0] = mantle_radius + 0.5 * lengths[0]
    centres[1:] = centres[0] + np.cumsum(0.5 * (lengths[:-1] + lengths[1:]))
    return TentacleShape(scales=scales, lengths=lengths, radii=radii, centres=centres)
