"""Lines that stand out on any ground: every line segment the renderer draws (goal
rings and paths, selection rings, plugins' markers) becomes a flat ribbon facing the
camera, a dark one `OUTLINE_PIXELS` wide under a bright one `LINE_PIXELS` wide in the
line's colour (a dull one lifted toward white). Light sand and grey rock alike then show a dark edge
and a bright core: the ring reads on both (a one-pixel line in a creature's colour
vanished on sand). One triangle list, one draw.
"""

from __future__ import annotations

import numpy as np

LINE_PIXELS = 2.2  # the bright core's width
OUTLINE_PIXELS = 5.0  # the dark edge's width (under the core)
OUTLINE = (0.06, 0.05, 0.05, 0.9)
LIFT = 0.5  # how far a dull core colour goes toward white (a bright one hardly moves)


def outlined_ribbons(segments: np.ndarray, eye: np.ndarray, metres_per_pixel: float) -> np.ndarray:
    """Triangles (6 * 2n, 7) of position and colour for segments (2n, 7) (end points, rgba):
    the dark edges first, the bright cores after. `metres_per_pixel` is a pixel's size at
    one metre from the eye."""
    if not len(segments):
        return np.zeros((0, 7), np.float32)
    ends = segments.reshape(-1, 2, 7).astype(np.float64)
    a, b = ends[:, 0, :3], ends[:, 1, :3]
    along = b - a
    view = 0.5 * (a + b) - eye
    side = np.empty_like(along)  # along x view, written out (np.cross's checks cost more)
    side[:, 0] = along[:, 1] * view[:, 2] - along[:, 2] * view[:, 1]
    side[:, 1] = along[:, 2] * view[:, 0] - along[:, 0] * view[:, 2]
    side[:, 2] = along[:, 0] * view[:, 1] - along[:, 1] * view[:, 0]
    length = np.sqrt(np.einsum("ij,ij->i", side, side))[:, None]
    side = np.where(length > 1e-12, side / np.maximum(length, 1e-12), 0.0)
    to_a, to_b = a - eye, b - eye
    reach_a = np.sqrt(np.einsum("ij,ij->i", to_a, to_a))[:, None] * metres_per_pixel / 2
    reach_b = np.sqrt(np.einsum("ij,ij->i", to_b, to_b))[:, None] * metres_per_pixel / 2
    core = ends[:, 0, 3:7].copy()
    dullness = 1.0 - core[:, :3] @ [0.2126, 0.7152, 0.0722]  # bright colours stay as they are
    core[:, :3] += LIFT * dullness[:, None] * (1.0 - core[:, :3])
    out = np.empty((2, len(a), 6, 7), np.float32)  # (pass, segment, corner, xyz rgba)
    edge = np.broadcast_to(np.asarray(OUTLINE), core.shape)
    for index, (width, colour) in enumerate(((OUTLINE_PIXELS, edge), (LINE_PIXELS, core))):
        a0, a1 = a - side * reach_a * width, a + side * reach_a * width
        b0, b1 = b - side * reach_b * width, b + side * reach_b * width
        for corner, point in enumerate((a0, b0, b1, a0, b1, a1)):
            out[index, :, corner, :3] = point
        out[index, :, :, 3:] = colour[:, None, :]
    return out.reshape(-1, 7)
