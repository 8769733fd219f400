"""The ground description (core): heights as MuJoCo's triangles give them, distances to
solids, and the static geoms every physics model gets."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from ecs_tentacles.ground import FLAT, StaticContact
from ecs_tentacles.terrain.ground import TerrainGround
from ecs_tentacles.terrain.heightfield import Heightfield
from ecs_tentacles.terrain.shapes import Solid, convex_planes


def _ray_height(model: mujoco.MjModel, x: float, y: float) -> float:
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    hit = np.zeros(1, dtype=np.int32)
    dist = mujoco.mj_ray(
        model, data, np.array([x, y, 50.0]), np.array([0, 0, -1.0]), None, 1, -1, hit
    )
    return 50.0 - dist


def _static_model(ground: TerrainGround) -> mujoco.MjModel:
    spec = mujoco.MjSpec()
    ground.add_to_spec(spec, StaticContact(1.0, 1, 2, [0.02, 1.0]))
    return spec.compile()


def test_heights_match_what_mujoco_collides_with() -> None:
    """The heightfield's `height` is the surface MuJoCo builds (rows along y from -y/2)."""
    rng = np.random.default_rng(4)
    heights = rng.uniform(-0.3, 0.5, size=(7, 9))
    ground = TerrainGround(Heightfield((4.0, 3.0), heights))
    model = _static_model(ground)
    points = rng.uniform([-1.99, -1.49], [1.99, 1.49], size=(40, 2))
    mine = ground.height(points)
    theirs = np.array([_ray_height(model, x, y) for x, y in points])
    np.testing.assert_allclose(mine, theirs, atol=1e-6)
    # the corner sample (row 0, column 0) is at (-x/2, -y/2)
    assert ground.height(np.array([[-2.0, -1.5]]))[0] == pytest.approx(heights[0, 0])


def test_the_plane_is_what_it_always_was() -> None:
    points = np.array([[0.3, -2.0, 0.25], [5.0, 1.0, -0.01]])
    np.testing.assert_array_equal(FLAT.distance(points), points[:, 2])
    np.testing.assert_array_equal(FLAT.height(points[:, :2]), [0.0, 0.0])
    spec = mujoco.MjSpec()
    FLAT.add_to_spec(spec, StaticContact(0.4, 1, 2, [0.006, 1.0]))
    model = spec.compile()
    assert model.ngeom == 1 and model.geom_type[0] == mujoco.mjtGeom.mjGEOM_PLANE


def test_solid_distances_and_normals() -> None:
    turn = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])  # 90 deg yaw
    box = Solid("box", np.array([1.0, 0.0, 0.5]), turn, (0.1, 2.0, 0.5))  # long along x now
    ground = TerrainGround(solids=(box,))
    assert box.signed_distance(np.array([[1.0, 0.0, 0.5]]))[0] == pytest.approx(-0.1)
    # beside the wall (its long side faces +-y after the turn)
    beside = np.array([[1.5, 0.3, 0.5]])
    assert ground.distance(beside)[0] == pytest.approx(0.2)
    np.testing.assert_allclose(ground.normal(beside)[0], [0.0, 1.0, 0.0], atol=1e-6)
    cube = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], float)
    piece = Solid("mesh", np.zeros(3), np.eye(3), pieces=(cube,), planes=(convex_planes(cube),))
    assert piece.signed_distance(np.array([[0.5, 0.5, 0.25]]))[0] == pytest.approx(-0.25)
    assert piece.signed_distance(np.array([[0.5, 0.5, 1.5]]))[0] == pytest.approx(0.5)
    assert TerrainGround(solids=(piece,)).inside_solid(
        np.array([[0.5, 0.5, 1.05], [3, 3, 3]]), 0.1
    ).tolist() == [0, -1]


def test_rays_and_the_topmost_surface() -> None:
    table = Solid("box", np.array([2.0, 0.0, 0.5]), np.eye(3), (0.5, 0.5, 0.5))
    ground = TerrainGround(Heightfield((8.0, 8.0), np.full((5, 5), 0.1)), (table,))
    assert ground.surface(np.array([[2.0, 0.0], [-2.0, 0.0]])).tolist() == pytest.approx([1.0, 0.1])
    hit = ground.ray(np.array([0.0, 0.0, 3.0]), np.array([1.0, 0.0, -1.0]))
    assert hit is not None and hit.tolist() == pytest.approx([2.0, 0.0, 1.0])  # the table top
    assert ground.ray(np.array([0.0, 0.0, 3.0]), np.array([0.0, 0.0, 1.0])) is None
    flat = FLAT.ray(np.array([1.0, 1.0, 2.0]), np.array([0.0, 1.0, -1.0]))
    assert flat is not None and flat.tolist() == pytest.approx([1.0, 3.0, 0.0])


def _field_and_points(seed: int, edges: list[list[float]]) -> tuple[Heightfield, np.ndarray]:
    """A 6 x 4 m field of random heights (33 x 49 samples) and points on it for the
    kernels' tests: 20,000 anywhere (some outside), a diagonal over sample lines, `edges`."""
    rng = np.random.default_rng(seed)
    field_ = Heightfield((6.0, 4.0), rng.uniform(-0.3, 0.5, size=(33, 49)))
    samples = np.linspace(-3.0, 3.0, 49)
    points = np.vstack([
        rng.uniform([-3.5, -2.5], [3.5, 2.5], size=(20_000, 2)),
        np.column_stack([samples, np.linspace(-2.0, 2.0, 49)]),
        edges,
    ])  # fmt: skip
    return field_, points


def test_the_height_kernel_gives_the_numpy_numbers_bit_for_bit(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Inside, on sample lines, on the borders and outside the field."""
    from ecs_tentacles.terrain import heightfield as module

    field_, points = _field_and_points(7, [[3.0, 0.0], [-3.0, 2.0], [0.0, -2.0],
                                           [3.0 + 1e-9, 0.0], [0.0, -50.0]])  # fmt: skip
    ground = TerrainGround(field_)
    assert module.KERNELS.get() is not None  # numba comes with the dev extra
    found = []
    for backend in ("auto", "numpy"):
        monkeypatch.setattr(module.KERNELS, "backend", backend)
        found.append(ground.height(points))
    np.testing.assert_array_equal(found[0], found[1])
    assert found[0][-1] == found[0][-2] == field_.heights.min()  # outside: the lowest


def test_the_normal_kernel_gives_the_numpy_numbers_bit_for_bit(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Inside, on sample lines, within half a cell of the borders and outside the field;
    signed zeros too (the numpy path adds 0.0 to the coordinate it does not move)."""
    from ecs_tentacles.terrain import heightfield as module

    dx, dy = 6.0 / 48, 4.0 / 32  # the field's cell
    edges = [[3.0 - 0.25 * dx, 0.0], [-3.0, 2.0 - 0.5 * dy], [-0.0, -0.0], [0.0, -50.0]]
    field_, points = _field_and_points(8, edges)
    assert field_.cell == (dx, dy)
    assert module.KERNELS.get() is not None  # numba comes with the dev extra
    found = []
    for backend in ("auto", "numpy"):
        monkeypatch.setattr(module.KERNELS, "backend", backend)
        found.append(field_.slope_normal(points))
        found.append(field_.slope_normal(points[:, :2][::3]))  # a strided view
    for kernel, numpy in zip(found[:2], found[2:], strict=True):
        assert kernel.tobytes() == numpy.tobytes()
    assert np.allclose(np.linalg.norm(found[0], axis=1), 1.0) and (found[0][:, 2] > 0).all()
    assert (found[0][-1] == [0.0, 0.0, 1.0]).all()  # outside: the flat lowest plane


def test_a_sphere_touches_an_obstacle_as_each_obstacle_alone_decides() -> None:
    """Culling every obstacle at once drops no touch and adds none: sphere by sphere, an
    obstacle whose bounding sphere it meets and whose signed distance is within its reach
    (a convex mesh's is the planes' lower bound: the cull counts too)."""
    rng = np.random.default_rng(5)
    turn = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    cube = np.array([[x, y, z] for x in (-0.3, 0.3) for y in (-0.3, 0.3) for z in (0, 0.6)])
    solids = (
        Solid("box", np.array([1.0, 0.0, 0.5]), turn, (0.1, 2.0, 0.5)),
        Solid("sphere", np.array([-2.0, 1.0, 0.2]), np.eye(3), (0.8,)),
        Solid("cylinder", np.array([0.0, -3.0, 0.0]), np.eye(3), (0.5, 1.0)),
        Solid("mesh", np.array([3.0, 3.0, 0.0]), np.eye(3), pieces=(cube,),
              planes=(convex_planes(cube),)),
    )  # fmt: skip
    ground = TerrainGround(solids=solids)
    centres = rng.uniform([-5.0, -5.0, -0.5], [5.0, 5.0, 1.5], size=(400, 3))
    reach = rng.uniform(0.0, 1.5, size=400)
    reach[:5] = 0.0  # a point: inside an obstacle or not
    touched = ground.touches_obstacle(centres, reach)
    each = [
        (np.linalg.norm(centres - solid.position, axis=1) <= reach + solid.bound)
        & (solid.signed_distance(centres) <= reach)
        for solid in solids
    ]
    assert (touched == np.any(each, axis=0)).all()
    assert all(e.any() for e in each) and 40 < touched.sum() < 360  # every obstacle, both answers
    assert not TerrainGround().touches_obstacle(centres, reach).any()  # no obstacles


def test_the_normal_under_points_among_obstacles_is_the_slope_of_the_topmost_surface() -> None:
    """Over the heightfield and over obstacles' tops: the surface's central differences,
    NORMAL_SPAN either way, normalised; the same bits as asking side by side."""
    from ecs_tentacles.terrain.ground import NORMAL_SPAN

    rng = np.random.default_rng(9)
    field_ = Heightfield((8.0, 8.0), rng.uniform(-0.2, 0.3, size=(17, 17)))
    solids = (
        Solid("box", np.array([1.0, 0.0, 0.5]), np.eye(3), (0.5, 0.5, 0.5)),
        Solid("sphere", np.array([-2.0, 1.0, 0.2]), np.eye(3), (0.8,)),
    )
    ground = TerrainGround(field_, solids)
    xy = np.vstack([rng.uniform(-4.5, 4.5, size=(300, 2)), [[1.0, 0.0], [-2.0, 1.0]]])
    normals = ground.normal_under(xy)
    ex, ey = np.array([NORMAL_SPAN, 0.0]), np.array([0.0, NORMAL_SPAN])
    gx = (ground.surface(xy + ex) - ground.surface(xy - ex)) / (2 * NORMAL_SPAN)
    gy = (ground.surface(xy + ey) - ground.surface(xy - ey)) / (2 * NORMAL_SPAN)
    n = np.stack([-gx, -gy, np.ones_like(gx)], axis=1)
    assert normals.tobytes() == (n / np.linalg.norm(n, axis=1, keepdims=True)).tobytes()
    assert (normals[-2:] == [0.0, 0.0, 1.0]).all()  # on the box's top and the sphere's crown
    assert (np.abs(normals[:300, :2]) > 1e-6).any(axis=1).sum() > 200  # sloped elsewhere
