"""Synthetic rig inputs for benchmarks and tests: guides on a sphere, random controls.

bind, values = synthetic_rig(10_000, points=8, controls=16, seed=0)
local = local_frames(bind, values)
"""

from __future__ import annotations

import numpy as np

from ecs_tentacles.fur.groom import arc_shapes
from ecs_tentacles.fur.rig import F32, Bind, ControlValues
from ecs_tentacles.fur.vectors import clamp_to_cap, cross, dot, normalize


def synthetic_rig(
    guides: int,
    points: int = 8,
    controls: int = 16,
    seed: int = 0,
    radius: float = 0.2,
    length: float = 0.05,
    bend_deg: float = 0.0,
    min_elevation_deg: float = 3.0,
) -> tuple[Bind, ControlValues]:
    """Guides rooted on a sphere of `radius`, resting 10 degrees above it; random controls.

    Every behaviour value is drawn in [0, 1] (random twist up to 45 degrees); controls lie
    within 3 radii of the centre, each moved a little from its rest position.
    """
    rng = np.random.default_rng(seed)
    normal = normalize(rng.normal(size=(3, guides)).astype(F32))
    tangent = normalize(cross(normal, normalize(rng.normal(size=(3, guides)).astype(F32))))
    rest = normalize(
        F32(np.cos(np.radians(10.0))) * tangent + F32(np.sin(np.radians(10.0))) * normal
    )
    bend = np.radians(bend_deg)
    floor = np.full(guides, np.tan(np.radians(min_elevation_deg) + 0.5 * bend), dtype=F32)
    rest = clamp_to_cap(rest, normal, floor)
    rest_sin = dot(rest, normal)
    shape = arc_shapes(np.full(guides, length), points, bend)
    shape_h = np.ones((guides, points, 4), dtype=F32)
    shape_h[..., :3] = shape
    bind = Bind(
        root=(radius * normal).astype(F32),
        basis=np.stack([tangent, cross(normal, tangent), normal]),
        rest_cos=np.sqrt(1.0 - rest_sin * rest_sin),
        rest_sin=rest_sin,
        tan_min=floor,
        multiplier=rng.uniform(-1.0, 1.0, guides).astype(F32),
        control=np.sort(rng.integers(0, controls, guides)),  # grouped, as the builder does
        body=np.zeros(guides, dtype=np.int64),
        shape_h=shape_h,
    )
    values = ControlValues(
        lift=rng.random(controls).astype(F32),
        aim=rng.random(controls).astype(F32),
        direction=rng.random(controls).astype(F32),
        twist=(rng.random(controls) * np.pi / 4).astype(F32),
        position=(rng.uniform(-3.0, 3.0, (3, controls)) * radius).astype(F32),
        offset=rng.normal(scale=0.5, size=(3, controls)).astype(F32),
    )
    return bind, values
