"""Rings and polylines laid on the ground, as line-list vertices for the `Lines` entries
(`ecs_tentacles.render.registries`): goal rings, the director's formation marks.

Pure numpy: plugins import it in headless worlds too.
"""

from __future__ import annotations

from typing import Protocol

import numpy as np


def line_segments(polyline: np.ndarray, colour: np.ndarray) -> np.ndarray:
    """Line-list vertices (2(n-1), 7) for a polyline (n, 3) in one rgba colour."""
    starts, ends = polyline[:-1], polyline[1:]
    pairs = np.empty((2 * len(starts), 3))
    pairs[0::2], pairs[1::2] = starts, ends
    return np.hstack([pairs, np.tile(colour, (len(pairs), 1))])


RING_SEGMENTS = 48
_ANGLES = np.linspace(0, 2 * np.pi, RING_SEGMENTS + 1)
CIRCLE = np.stack([np.cos(_ANGLES), np.sin(_ANGLES), np.zeros_like(_ANGLES)], axis=1)
"""A unit circle in the ground plane, (RING_SEGMENTS + 1, 3): scale and move it for rings."""


class HasSurface(Protocol):
    """What `draped` needs of a ground: the topmost surface under points (`Ground`)."""

    def surface(self, xy: np.ndarray) -> np.ndarray: ...


def draped(points: np.ndarray, ground: HasSurface, lift: float) -> np.ndarray:
    """`points` (n, 3) put on the topmost surface under them (the ground, or a solid: a
    ramp, a platform), `lift` m above it: a ring round a goal or a creature on a hillside
    or a ledge follows it instead of sinking into it."""
    out = np.array(points, dtype=np.float64)
    out[:, 2] = ground.surface(out[:, :2]) + lift
    return out
