"""Guides on the mantle: generation (count, density, regions, flow, seed) and listing."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose

from ecs_tentacles.fur import groom
from ecs_tentacles.fur.presets import resolve

R, H = 0.15, 0.2


def spec(**fields: object) -> dict[str, object]:
    return dict(resolve({"groom": fields})["groom"])


def on_surface(points: np.ndarray) -> np.ndarray:
    """Distance of each point from the mantle's surface (wall or top cap)."""
    rho = np.linalg.norm(points[:, :2], axis=1)
    wall = np.abs(rho - R) + np.maximum(np.abs(points[:, 2]) - H / 2, 0)
    top = np.abs(points[:, 2] - H / 2) + np.maximum(rho - R, 0)
    return np.asarray(np.minimum(wall, top))


def test_defaults_and_determinism() -> None:
    a = groom.generate(spec(), R, H)
    b = groom.generate(spec(), R, H)
    assert len(a.root) == 200 and a.shape.shape == (200, 8, 3)
    for field in ("root", "normal", "rest", "side", "length", "multiplier", "shape"):
        assert_allclose(getattr(a, field), getattr(b, field), rtol=0, atol=0)
    other = groom.generate(spec(seed=1), R, H)
    assert not np.allclose(other.root, a.root)


def test_roots_lie_on_the_skin_with_unit_outward_normals() -> None:
    g = groom.generate(spec(count=500), R, H)
    assert on_surface(g.root).max() < 1e-12
    assert_allclose(np.linalg.norm(g.normal, axis=1), 1.0, atol=1e-12)
    top = g.normal[:, 2] > 0.5
    assert_allclose(g.root[top, 2], H / 2, atol=1e-12)
    assert_allclose(g.normal[~top] * R, g.root[~top] * (1, 1, 0), atol=1e-12)
    assert 0 < top.sum() < 500


@pytest.mark.parametrize(
    ("region", "rule"),
    [
        ("top", lambda p, n: n[:, 2] == 1.0),
        ("side", lambda p, n: n[:, 2] == 0.0),
        ("back", lambda p, n: p[:, 2] >= 0.0),
        ("rear", lambda p, n: p[:, 0] <= 1e-12),
        ("front", lambda p, n: p[:, 0] >= -1e-12),
    ],
)
def test_regions(region: str, rule: object) -> None:
    g = groom.generate(spec(count=300, region=region), R, H)
    assert len(g.root) == 300
    assert np.all(rule(g.root, g.normal))  # type: ignore[operator]


def test_density_sets_the_count_from_the_area() -> None:
    area = np.pi * R**2 + 2 * np.pi * R * H
    assert groom.region_area("all", R, H) == pytest.approx(area)
    assert groom.region_area("back", R, H) == pytest.approx(np.pi * R**2 + np.pi * R * H)
    g = groom.generate(spec(density=2000, count=5), R, H)
    assert len(g.root) == round(2000 * area)


def test_rest_directions_lie_close_to_the_skin_and_flow_to_the_rear() -> None:
    g = groom.generate(spec(count=400, rest_angle_deg=12), R, H)
    elevation = np.degrees(np.arcsin(np.sum(g.rest * g.normal, axis=1)))
    assert_allclose(elevation, 12.0, atol=1e-9)
    top = g.normal[:, 2] > 0.5
    assert np.all(g.rest[top, 0] < 0)  # on the top they flow toward -x
    assert_allclose(np.cross(g.normal, g.rest), g.side * np.cos(np.radians(12)), atol=1e-12)


def test_flow_down_goes_down_the_wall_and_out_from_the_crown() -> None:
    g = groom.generate(spec(count=400, flow="down"), R, H)
    wall = g.normal[:, 2] < 0.5
    assert np.all(g.rest[wall, 2] < 0)
    top = ~wall
    outward = np.sum(g.rest[top, :2] * g.root[top, :2], axis=1)
    assert np.mean(outward > 0) > 0.9


def test_lengths_jitter_and_multipliers() -> None:
    g = groom.generate(spec(count=1000, length=0.1, length_jitter=0.5), R, H)
    assert g.length.min() >= 0.05 and g.length.max() <= 0.1
    assert g.length.std() > 0.01
    assert g.multiplier.min() >= -1 and g.multiplier.max() <= 1
    assert (g.multiplier < 0).sum() > 400 and (g.multiplier > 0).sum() > 400
    assert_allclose(g.shape[:, -1, 0], g.length)  # straight: the tip is `length` along


def test_bent_guides_are_arcs_of_their_length_curving_to_the_skin() -> None:
    g = groom.generate(spec(count=50, bend_deg=60, points=16), R, H)
    steps = np.linalg.norm(np.diff(g.shape, axis=1), axis=2).sum(axis=1)
    assert_allclose(steps, g.length, rtol=2e-3)  # polyline of an arc: slightly shorter
    assert np.all(g.shape[:, 1:, 1] < 0)  # toward -up, the skin side


def test_listed_guides_snap_to_the_nearest_skin_point() -> None:
    guides = [
        {"points": [[0.2, 0.0, 0.0], [0.3, 0.0, 0.05]]},  # outside the wall
        {"points": [[0.0, 0.05, 0.12], [0.0, 0.05, 0.2], [0.02, 0.05, 0.3]]},  # above the top
    ]
    g = groom.explicit(guides, 5, R, H)
    assert_allclose(g.root, [[R, 0, 0], [0, 0.05, H / 2]], atol=1e-12)
    assert_allclose(g.normal, [[1, 0, 0], [0, 0, 1]], atol=1e-12)
    assert_allclose(g.rest[0], np.array([0.1, 0, 0.05]) / np.hypot(0.1, 0.05), atol=1e-12)
    first = np.linalg.norm([0.1, 0.05])
    assert_allclose(g.length[0], first)
    assert_allclose(g.shape[0, :, 0], np.linspace(0, first, 5), atol=1e-12)
    assert_allclose(g.shape[0, :, 1:], 0, atol=1e-12)
    assert_allclose(g.shape[1, 0], 0, atol=1e-12)


def test_resample_keeps_the_polyline() -> None:
    line = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0.0]])
    assert_allclose(
        groom.resample(line, 5), [[0, 0, 0], [0.5, 0, 0], [1, 0, 0], [1, 0.5, 0], [1, 1, 0]]
    )
