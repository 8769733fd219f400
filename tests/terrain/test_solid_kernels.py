"""The terrain's sphere kernels (`terrain.solid_kernels`) give numpy's numbers bit for
bit, spheres mixed with other solids, points on the very edges of their tests."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from ecs_tentacles.terrain import ground as ground_module
from ecs_tentacles.terrain.ground import NEAR, TerrainGround
from ecs_tentacles.terrain.heightfield import Heightfield
from ecs_tentacles.terrain.shapes import Solid

pytest.importorskip("numba")
SPHERES = 10  # in `_ground`
EDGES = SPHERES * 4 * 3  # the points `_points` puts on each sphere's edges


def _ground() -> TerrainGround:
    """Rocks on a bumpy field: spheres (one turned), a box and a cylinder among them."""
    rng = np.random.default_rng(7)
    turned = Rotation.from_euler("xyz", [30.0, 10.0, 70.0], degrees=True).as_matrix()
    solids = [
        Solid("sphere", np.array([x, y, z]), np.eye(3), (r,))
        for x, y, z, r in rng.uniform([-2.5, -2.5, -0.2, 0.1], [2.5, 2.5, 0.3, 0.6], (9, 4))
    ]
    solids.append(Solid("sphere", np.array([0.5, 0.0, 0.1]), turned, (0.5,)))
    solids.append(Solid("box", np.array([1.0, -1.0, 0.1]), turned, (0.3, 0.2, 0.4)))
    solids.append(Solid("cylinder", np.array([-1.0, 1.0, 0.0]), np.eye(3), (0.3, 0.5)))
    heights = rng.uniform(-0.1, 0.2, size=(12, 14))
    return TerrainGround(Heightfield((6.0, 6.0), heights), tuple(solids))


def _points(ground: TerrainGround) -> np.ndarray:
    """Random points over the rocks, and points on each sphere's tests' edges: its centre,
    its surface (its rim seen from above), its bounding sphere plus NEAR, and 0.1 m out
    (where `_answers` gives the ball just that reach)."""
    rng = np.random.default_rng(3)
    points = [rng.uniform([-3.0, -3.0, -0.3], [3.0, 3.0, 1.0], (3000, 3))]
    for solid in ground.solids:
        if solid.kind != "sphere":
            continue
        r, c = solid.size[0], solid.position
        for gap in (0.0, r, r + NEAR, r + 0.1):  # (to rounding)
            points.append(c + np.array([[gap, 0.0, 0.0], [0.0, -gap, 0.0], [0.0, 0.0, gap]]))
    return np.vstack(points)


def _answers(ground: TerrainGround, points: np.ndarray) -> list[np.ndarray]:
    rng = np.random.default_rng(5)
    reach = rng.uniform(0.0, 0.4, len(points))
    edges = reach[-EDGES:].reshape(SPHERES, 4, 3)
    edges[:] = 1e-9  # a ball on a sphere's surface touches it
    spheres = [s for s in ground.solids if s.kind == "sphere"]
    for sphere, out, ball in zip(
        spheres, points[-EDGES:].reshape(SPHERES, 4, 3, 3)[:, 3], edges[:, 3], strict=True
    ):
        ball[:] = sphere.signed_distance(out)  # a ball just reaching it: touching
    return [
        ground.surface(points[:, :2]),
        ground.distance(points),
        ground.touches_obstacle(points, reach),
        ground.normal_under(points[:, :2]),
    ]


def test_the_sphere_kernels_give_numpys_numbers_bit_for_bit(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    points = _points(_ground())
    found = {}
    for backend in ("numpy", "auto"):
        monkeypatch.setattr(ground_module.KERNELS, "backend", backend)
        ground = _ground()  # its caches made under this backend
        found[backend] = _answers(ground, points)
    assert ground_module.KERNELS.get() is not None
    for numpy_answer, kernel_answer in zip(found["numpy"], found["auto"], strict=True):
        assert numpy_answer.tobytes() == kernel_answer.tobytes()
    # per sphere, gap (centre, surface, bound, 0.1 m out) and direction (x, y, z)
    surface, distance, touches, _ = (a[-EDGES:].reshape(SPHERES, 4, 3, -1) for a in found["auto"])
    spheres = [s for s in _ground().solids if s.kind == "sphere"]
    tops = np.array([s.position[2] + s.size[0] for s in spheres])
    assert np.all(surface[:, 0, 0, 0] >= tops - 1e-12)  # above a centre: at least its top
    assert touches[:, [0, 1, 3]].all()  # at the centre, on the surface, just reaching it
    # the nearest surface: on a sphere's, or inside it by its radius (or another solid's)
    assert np.all(distance[:, 1, :, 0] <= 1e-12)
    radii = np.array([s.size[0] for s in spheres])
    assert np.all(distance[:, 0, :, 0] <= -radii[:, None] + 1e-12)


def test_a_turned_sphere_is_as_far_as_an_unturned_one() -> None:
    turned = Rotation.from_euler("xyz", [40.0, 0.0, 20.0], degrees=True).as_matrix()
    centre = np.array([0.2, -0.1, 0.3])
    points = np.random.default_rng(1).normal(size=(50, 3))
    sphere = Solid("sphere", centre, turned, (0.4,))
    expected = np.linalg.norm(points - centre, axis=1) - 0.4
    assert np.array_equal(sphere.signed_distance(points), expected)


def test_one_reach_for_every_ball_is_each_balls_reach() -> None:
    """`touches_obstacle` given a single reach (not one a ball) reads it for every ball,
    with the kernels as with numpy: none reads past the end of a one-entry array."""
    ground = _ground()
    points = _points(ground)
    one = ground.touches_obstacle(points, np.array(0.2))
    each = ground.touches_obstacle(points, np.full(len(points), 0.2))
    assert np.array_equal(one, each) and one.any() and not one.all()


def test_the_bounds_kernel_picks_numpys_points_for_each_solid(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Which points lie within each solid's bounding sphere (points (n, 3)) or circle
    (n, 2), grown by one pad or a pad a point: the same solids and rows with the kernel
    as with numpy, points exactly on a grown bound included."""
    rng = np.random.default_rng(11)
    ground = _ground()
    centres, bounds = ground._bounds()
    pads = rng.uniform(0.0, 0.3, len(centres))
    on_edge = ground._positions() + (bounds + pads)[:, None] * np.array([1.0, 0.0, 0.0])
    points = np.vstack([rng.uniform([-3.0, -3.0, -0.3], [3.0, 3.0, 1.0], (2000, 3)), on_edge])
    pad = np.concatenate([rng.uniform(0.0, 0.3, 2000), pads])
    found = {}
    for backend in ("numpy", "auto"):
        monkeypatch.setattr(ground_module.KERNELS, "backend", backend)
        found[backend] = [
            [(k, rows.tolist()) for k, rows in ground._under_bounds(query, grow)]
            for query, grow in ((points, pad), (points, 0.25), (points[:, :2], 0.0))
        ]
    assert found["numpy"] == found["auto"]
    assert all(len(pairs) > 3 for pairs in found["auto"])


def _rocks() -> TerrainGround:
    """Rocks as the rocky preset makes them (convex meshes), turned, with a sphere, on a
    bumpy field: the convex pieces' kernels meet every kind of query."""
    from ecs_tentacles.terrain.rocks import rock_vertices
    from ecs_tentacles.terrain.shapes import convex_planes

    rng = np.random.default_rng(17)
    solids = [Solid("sphere", np.array([0.0, 0.0, 0.1]), np.eye(3), (0.4,))]
    for seed, (x, y, yaw) in enumerate(rng.uniform([-2.5, -2.5, 0.0], [2.5, 2.5, 180.0], (12, 3))):
        vertices = rock_vertices(rng.uniform(0.3, 1.2, 3), seed)
        turn = Rotation.from_euler("z", yaw, degrees=True).as_matrix()
        solids.append(Solid("mesh", np.array([x, y, 0.1]), turn, pieces=(vertices,),
                            planes=(convex_planes(vertices),)))  # fmt: skip
    heights = rng.uniform(-0.1, 0.2, size=(12, 14))
    return TerrainGround(Heightfield((6.0, 6.0), heights), tuple(solids))


def test_the_convex_piece_kernels_give_numpys_numbers_bit_for_bit(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The distance from points and which balls touch a rock, by the pieces' kernels and
    by numpy's (points, pieces) arrays: the same bits, points exactly on a piece's
    bounding sphere grown by NEAR (the distance's cut) and by a ball's reach included."""
    rng = np.random.default_rng(19)
    pieces = _rocks()._pieces()
    edge = np.array([1.0, 0.0, 0.0])
    points = np.vstack([
        rng.uniform([-3.0, -3.0, -0.3], [3.0, 3.0, 1.2], (4000, 3)),
        pieces.centres + (pieces.bounds + NEAR)[:, None] * edge,  # on the distance's cut
        pieces.centres + (pieces.bounds + 0.25)[:, None] * edge,  # on a 0.25 m ball's
    ])  # fmt: skip
    reach = rng.uniform(0.0, 0.4, len(points))
    reach[-len(pieces) :] = 0.25
    found = {}
    for backend in ("numpy", "auto"):
        monkeypatch.setattr(ground_module.KERNELS, "backend", backend)
        ground = _rocks()
        found[backend] = [ground.distance(points), ground.touches_obstacle(points, reach)]
    assert ground_module.KERNELS.get() is not None
    for numpy_answer, kernel_answer in zip(found["numpy"], found["auto"], strict=True):
        assert numpy_answer.tobytes() == kernel_answer.tobytes()
    distance, touches = found["auto"]
    inside = np.zeros(len(points), bool)
    for solid in _rocks().solids[1:]:
        inside |= solid.signed_distance(points) < 0.0
    assert inside.sum() > 100 and np.all(distance[inside] < 0.0)  # inside a rock: negative
    assert touches[inside].all() and not touches.all()
