"""Fur controls drawn as small line shapes (sphere, cube, circle, diamond, arrow).

Line-list vertices (2n, 7: xyz rgba) join the renderer's one line batch, so the
markers cost no draw call of their own. The selected control is drawn white and
half as large again.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.fur.hooks import control_markers

if TYPE_CHECKING:
    from ecs_tentacles.host import Host


def _ring(axis: int, n: int = 16) -> np.ndarray:
    """Segments (n, 2, 3) of a unit circle about `axis`."""
    a = np.linspace(0.0, 2 * np.pi, n + 1)
    c, s = np.cos(a), np.sin(a)
    i, j = [k for k in range(3) if k != axis]
    points = np.zeros((n + 1, 3))
    points[:, i], points[:, j] = c, s
    return np.stack([points[:-1], points[1:]], axis=1)


def _cube() -> np.ndarray:
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)
    edges = [(a, b) for a in range(8) for b in range(a + 1, 8) if bin(a ^ b).count("1") == 1]
    lines: np.ndarray = corners[np.array(edges)] * 0.8
    return lines


def _diamond() -> np.ndarray:
    tips = np.array([[0, 0, 1.3], [0, 0, -1.3]], float)
    ring = np.array([[1, 0, 0], [0, 1, 0], [-1, 0, 0], [0, -1, 0]], float)
    edges = [(t, r) for t in tips for r in ring] + [(ring[k], ring[(k + 1) % 4]) for k in range(4)]
    return np.array(edges)


def _arrow() -> np.ndarray:
    shaft = [([0, 0, -1], [0, 0, 1])]
    head = [([0, 0, 1], [x, y, 0.4]) for x, y in ((0.5, 0), (-0.5, 0), (0, 0.5), (0, -0.5))]
    return np.array(shaft + head, float)


SHAPES = {
    "sphere": np.concatenate([_ring(0), _ring(1), _ring(2)]),
    "circle": _ring(2, 24),
    "cube": _cube(),
    "diamond": _diamond(),
    "arrow": _arrow(),
}


def marker_lines(
    world: Host, selected: int | None = None, creature: int | None = None
) -> np.ndarray:
    """Line-list vertices (2n, 7) of every fur control (`creature`: only that creature
    entity's); `selected`: the highlighted control's entity."""
    parts = []
    for marker in control_markers(world, creature):
        chosen = marker.entity == selected
        template = SHAPES.get(marker.shape, SHAPES["sphere"])
        segments = marker.position + template * marker.size * (1.5 if chosen else 1.0)
        colour = (1.0, 1.0, 1.0, 1.0) if chosen else (*marker.colour, 1.0)
        out = np.empty((len(segments) * 2, 7), np.float32)
        out[:, :3] = segments.reshape(-1, 3)
        out[:, 3:] = colour
        parts.append(out)
    return np.vstack(parts) if parts else np.zeros((0, 7), np.float32)
