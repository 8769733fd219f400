"""The mesh obstacles' pieces answered in one pass (`terrain.convex_pieces`) give what
each solid's own `signed_distance` gives: `distance` and `touches_obstacle` on rocks
(and a box beside them, still asked solid by solid) equal the solid-by-solid answer."""

from __future__ import annotations

import numpy as np

from ecs_tentacles.terrain.ground import NEAR, TerrainGround
from ecs_tentacles.terrain.scene_ground import build_ground

TERRAIN = {
    "obstacles": [
        {"shape": "rock", "position": [0.0, 0.0, 0.1], "size": [0.9, 0.6, 0.5], "seed": 1},
        {"shape": "rock", "position": [0.7, 0.2, 0.0], "size": [0.5, 0.5, 0.4], "seed": 2,
         "rotation_deg": [10, 0, 60]},
        {"shape": "box", "position": [-0.8, 0.0, 0.1], "size": [0.4, 0.4, 0.4]},
    ]
}  # fmt: skip


def _solid_by_solid(
    ground: TerrainGround, points: np.ndarray, reach: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    best, touches = points[:, 2].copy(), np.zeros(len(points), dtype=bool)
    for solid in ground.solids:
        gap = np.linalg.norm(points - solid.position, axis=1)
        near = gap <= solid.bound + NEAR
        best[near] = np.minimum(best[near], solid.signed_distance(points[near]))
        within = gap <= solid.bound + reach
        touches[within] |= solid.signed_distance(points[within]) <= reach[within]
    return best, touches


def test_rocks_in_one_pass_answer_as_each_rock_does() -> None:
    ground = build_ground(TERRAIN, None)
    assert isinstance(ground, TerrainGround) and len(ground._pieces()) == 2
    rng = np.random.default_rng(3)
    points = rng.uniform([-1.5, -1.0, -0.1], [1.5, 1.0, 0.8], size=(4000, 3))
    reach = rng.uniform(0.0, 0.4, size=len(points))
    best, touches = _solid_by_solid(ground, points, reach)
    np.testing.assert_allclose(ground.distance(points), best, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(ground.touches_obstacle(points, reach), touches)
    assert (best < 0).sum() > 100 and 0 < touches.mean() < 1  # inside and outside both
