"""How far apart two creatures' bodies are (negative: how deep they interpenetrate).

Measured on the geometry the physics uses, from the Transform store: link capsules
(segment along the link's +x, radius) exactly, segment to segment
(`ecs_tentacles.scene.overlap.segment_distances`, shared with the build check); the mantle
cylinder against link capsules by sampling each link's segment at a few points
(exact point-to-cylinder distances). For the tests (how close did two creatures
come?); never per frame in the engine.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.components import Creature, Link, Tentacle, Transform
from ecs_tentacles.numeric.quaternions import quat_rotate
from ecs_tentacles.scene.overlap import segment_distances

if TYPE_CHECKING:
    from ecs_tentacles.physics.host import PhysicsHost

SAMPLES = 9  # points along a link tested against a mantle


def creature_shapes(world: PhysicsHost, creature_entity: int) -> dict[str, np.ndarray]:
    """The creature's capsules (start, end, radius) and mantle (centre, axis, radius, half)."""
    creature = world.component(creature_entity, Creature)
    links = [
        link_entity
        for tentacle_entity in creature.tentacles
        for link_entity in world.component(tentacle_entity, Tentacle).links
    ]
    shapes = [world.component(e, Link) for e in links]
    rows = [world.component(e, Transform).row for e in links]
    mantle = world.component(creature_entity, Transform)
    pos, quat = mantle.store.pos[rows], mantle.store.quat[rows]  # every link at once
    along = np.zeros((len(links), 3))
    along[:, 0] = [0.5 * link.length for link in shapes]
    half = quat_rotate(quat, along) if links else along
    return {
        "start": pos - half,
        "end": pos + half,
        "radius": np.array([link.radius for link in shapes], dtype=np.float64),
        "centre": np.array(mantle.pos),
        "axis": quat_rotate(mantle.quat, np.array([0.0, 0.0, 1.0])),
        "mantle": np.array([creature.mantle_radius, 0.5 * creature.mantle_height]),
    }


def bounding_sphere(shapes: dict[str, np.ndarray]) -> tuple[np.ndarray, float]:
    """A sphere round every shape of `creature_shapes`: the mantle's centre and the
    farthest capsule or mantle surface from it."""
    centre = shapes["centre"]
    ends = np.concatenate([shapes["start"], shapes["end"]]) - centre
    far = np.linalg.norm(ends, axis=1) + np.concatenate([shapes["radius"], shapes["radius"]])
    return centre, max(float(far.max(initial=0.0)), float(np.hypot(*shapes["mantle"])))


def clearance(sa: dict[str, np.ndarray], sb: dict[str, np.ndarray]) -> float:
    """Smallest gap (metres) between two creatures given by their `creature_shapes`;
    negative when they overlap."""
    gaps = [capsule_clearance(sa, sb), _capsules_to_mantle(sa, sb), _capsules_to_mantle(sb, sa)]
    return float(min(gaps))


def capsule_clearance(sa: dict[str, np.ndarray], sb: dict[str, np.ndarray]) -> float:
    """Smallest gap (metres) between the link capsules of two `creature_shapes`, every
    pair of axes exactly; negative when they overlap."""
    axes = segment_distances(
        sa["start"][:, None], sa["end"][:, None], sb["start"][None], sb["end"][None]
    )
    return float((axes - sa["radius"][:, None] - sb["radius"][None, :]).min(initial=np.inf))


def _capsules_to_mantle(capsules: dict[str, np.ndarray], other: dict[str, np.ndarray]) -> float:
    if not len(capsules["radius"]):
        return np.inf
    t = np.linspace(0.0, 1.0, SAMPLES)[None, :, None]
    points = capsules["start"][:, None] + t * (capsules["end"] - capsules["start"])[:, None]
    rel = points - other["centre"]
    along = rel @ other["axis"]
    radial = np.linalg.norm(rel - along[..., None] * other["axis"], axis=-1)
    radius, half = other["mantle"]
    out_r, out_h = radial - radius, np.abs(along) - half
    outside = np.hypot(np.maximum(out_r, 0.0), np.maximum(out_h, 0.0))
    inside = np.minimum(np.maximum(out_r, out_h), 0.0)
    gap = outside + inside - capsules["radius"][:, None]
    return float(gap.min())
