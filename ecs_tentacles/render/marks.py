"""What the plugins hand the renderer each frame, as instance arrays: their spheres
(`Spheres`, and `OverlaySpheres` outside the clean view: one instanced batch) and their
line segments (`Lines`, `OverlayLines`), with a ring round each selected creature.

Reads the world's registries (`ecs_tentacles.render.registries`), the body poses and
the renderer's per-creature tables it is given; writes nothing (returns the arrays
`Renderer._fill` uploads).
"""

from __future__ import annotations

import numpy as np

from ecs_tentacles.ground import Ground
from ecs_tentacles.render.gpu import INSTANCE_FLOATS
from ecs_tentacles.render.registries import Lines as LineEntries
from ecs_tentacles.render.registries import OverlayLines, OverlaySpheres, RenderView, Spheres
from ecs_tentacles.render.rings import CIRCLE, draped
from ecs_tentacles.world import World


def sphere_instances(world: World, clean: bool) -> np.ndarray:
    """The plugins' spheres (attached suckers, threats): one instanced batch (in the
    clean view, the `Spheres` entries' only)."""
    entries = [*world.registry(Spheres)]
    if not clean:
        entries += world.registry(OverlaySpheres)
    markers = [m for spheres in entries for m in spheres(world)]
    count = sum(len(m.positions) for m in markers)
    out = np.zeros((count, INSTANCE_FLOATS), np.float32)
    out[:, 3] = 1.0
    start = 0
    for marker in markers:
        end = start + len(marker.positions)
        out[start:end, 0:3] = marker.positions
        out[start:end, 7:11] = (*marker.size, 0.0)
        out[start:end, 11:15] = marker.rgba
        start = end
    return out


def plugin_segments(world: World, view: RenderView, clean: bool) -> list[np.ndarray]:
    """The plugins' line segments, (2n, 7) arrays (in the clean view, the `Lines`
    entries' only)."""
    entries = [*world.registry(LineEntries)]
    if not clean:
        entries += world.registry(OverlayLines)
    segments = [np.zeros((0, 7))]
    for lines in entries:
        segments += lines(world, view)
    return segments


def selection_rings(centres: np.ndarray, radii: np.ndarray, ground: Ground) -> np.ndarray:
    """A white ring of radius `radii[i]` round each of `centres` (n, 3), draped on
    `ground`: (2m, 7) segments, one pass for every ring."""
    rings = centres[:, None, :] + radii[:, None, None] * CIRCLE
    rings = draped(rings.reshape(-1, 3), ground, 0.01).reshape(rings.shape)
    pairs = np.stack([rings[:, :-1], rings[:, 1:]], axis=2).reshape(-1, 3)
    return np.hstack([pairs, np.ones((len(pairs), 4))])


def reach(
    pos: np.ndarray,
    mantle_radii: np.ndarray,
    mantle_rows: np.ndarray,
    link_rows: np.ndarray,
    link_creature: np.ndarray,
    link_radii: np.ndarray,
) -> np.ndarray:
    """Each drawn creature's reach in the ground plane now (m): its farthest link from
    its mantle (`link_creature`: each link's creature), at least 1.6 mantle radii."""
    out = 1.6 * mantle_radii.astype(np.float64)
    if len(link_rows):
        mantle = pos[mantle_rows[link_creature], :2]
        far = np.linalg.norm(pos[link_rows, :2] - mantle, axis=1)
        np.maximum.at(out, link_creature, far + link_radii)
    return out
