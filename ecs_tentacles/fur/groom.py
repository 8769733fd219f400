"""Guides on the mantle: generated from a groom spec, or listed explicitly.

The mantle is a cylinder along +z centred on its body's origin (radius R, half height
H). Roots, normals and rest directions are in that body-local frame, so guides follow
the creature. Regions: ``all`` (top cap and side wall), ``top``, ``side``, ``back``
(the dorsal surface: top cap and the upper half of the wall), ``rear`` (x < 0) and
``front`` (x > 0). A guide's rest direction lies `rest_angle` above the skin and
flows toward the rear (-x, a little down) or down the body (-z on the wall, outward
from the crown on the top). Explicit guides are snapped to the nearest surface point
(thesis 4.3: follicle at the closest point) with that point's normal.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ecs_tentacles.numeric.quaternions import cross

FLOWS = {"rear": (-1.0, 0.0, -0.3), "down": (-0.05, 0.0, -1.0)}
X_AXIS, Y_AXIS = np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0])  # fallback tangents
DOWN_OUTWARD = 0.8  # how strongly "down" flows outward from the crown on the top cap


@dataclass
class Guides:
    """Guides in a body's local frame; `shape` (n, points, 3) in rest-frame coordinates."""

    root: np.ndarray
    normal: np.ndarray
    rest: np.ndarray
    side: np.ndarray
    length: np.ndarray
    multiplier: np.ndarray
    shape: np.ndarray


def _unit(v: np.ndarray) -> np.ndarray:
    norm = np.linalg.norm(v, axis=-1, keepdims=True)
    return np.asarray(v / np.maximum(norm, 1e-15))


def _parts(region: str, radius: float, half: float) -> list[tuple[str, float, float, int]]:
    """(part, z_low, z_high, x_sign) pieces of a region; part is 'top' or 'side'."""
    top = ("top", half, half, 0)
    side = ("side", -half, half, 0)
    table = {
        "all": [top, side],
        "top": [top],
        "side": [side],
        "back": [top, ("side", 0.0, half, 0)],
        "rear": [("top", half, half, -1), ("side", -half, half, -1)],
        "front": [("top", half, half, 1), ("side", -half, half, 1)],
    }
    return table[region]


def _part_area(part: tuple[str, float, float, int], radius: float) -> float:
    kind, low, high, sign = part
    full = np.pi * radius**2 if kind == "top" else 2 * np.pi * radius * (high - low)
    return float(full * (0.5 if sign else 1.0))


def region_area(region: str, radius: float, height: float) -> float:
    """Skin area (m^2) of `region` on a mantle of `radius` and `height`."""
    return sum(_part_area(p, radius) for p in _parts(region, radius, 0.5 * height))


def sample_surface(
    region: str, count: int, radius: float, height: float, rng: np.random.Generator
) -> tuple[np.ndarray, np.ndarray]:
    """`count` area-uniform points on `region` and their outward normals, (count, 3) each."""
    half = 0.5 * height
    parts = _parts(region, radius, half)
    areas = np.array([_part_area(p, radius) for p in parts])
    which = rng.choice(len(parts), size=count, p=areas / areas.sum())
    u, v = rng.random(count), rng.random(count)
    points = np.zeros((count, 3))
    normals = np.zeros((count, 3))
    for index, (part, low, high, sign) in enumerate(parts):
        mask = which == index
        span = np.pi if sign else 2 * np.pi
        start = {0: 0.0, 1: -0.5 * np.pi, -1: 0.5 * np.pi}[sign]
        angle = start + span * v[mask]
        if part == "top":
            r = radius * np.sqrt(u[mask])
            points[mask] = np.stack(
                [r * np.cos(angle), r * np.sin(angle), np.full_like(r, half)], 1
            )
            normals[mask] = (0.0, 0.0, 1.0)
        else:
            z = low + (high - low) * u[mask]
            ring = np.stack([np.cos(angle), np.sin(angle), np.zeros_like(angle)], 1)
            points[mask] = radius * ring + z[:, None] * np.array([0.0, 0.0, 1.0])
            normals[mask] = ring
    return points, normals


def tangent_flow(points: np.ndarray, normals: np.ndarray, flow: str, radius: float) -> np.ndarray:
    """Unit tangents (n, 3) of the groom's flow at `points`."""
    f = np.broadcast_to(np.array(FLOWS[flow]), points.shape).copy()
    if flow == "down":
        f[:, :2] += DOWN_OUTWARD * points[:, :2] / radius * (normals[:, 2:3] > 0.5)
    t = f - np.sum(f * normals, axis=1, keepdims=True) * normals
    flat = np.linalg.norm(t, axis=1) < 1e-9
    if flat.any():  # a pole of the flow: any tangent
        t[flat] = cross(normals[flat], Y_AXIS)
    return _unit(t)


def side_vectors(normal: np.ndarray, rest: np.ndarray) -> np.ndarray:
    """Rest-frame side vectors: normal x rest, normalised (any tangent if parallel)."""
    side = cross(normal, rest)  # (np.cross's arithmetic: the same bits, a fifth of the time)
    flat = np.linalg.norm(side, axis=1) < 1e-9
    if flat.any():
        fallback = cross(normal[flat], X_AXIS)
        weak = np.linalg.norm(fallback, axis=1) < 1e-9
        fallback[weak] = cross(normal[flat][weak], Y_AXIS)
        side[flat] = fallback
    return _unit(side)


def arc_shapes(length: np.ndarray, points: int, bend: float) -> np.ndarray:
    """Rest-frame points (n, points, 3) of guides bending `bend` radians toward the skin."""
    s = np.linspace(0.0, 1.0, points)[None, :] * length[:, None]
    if abs(bend) < 1e-9:
        return np.stack([s, np.zeros_like(s), np.zeros_like(s)], axis=-1)
    curvature = bend / length[:, None]
    theta = curvature * s
    axis = np.sin(theta) / curvature
    up = -(1.0 - np.cos(theta)) / curvature
    return np.stack([axis, up, np.zeros_like(s)], axis=-1)


def generate(groom: dict[str, Any], radius: float, height: float) -> Guides:
    """Guides from a groom spec (count or density, region, length, flow, seed...)."""
    rng = np.random.default_rng(groom["seed"])
    region = groom["region"]
    count = groom["count"]
    if "density" in groom:
        count = round(groom["density"] * region_area(region, radius, height))
    root, normal = sample_surface(region, count, radius, height, rng)
    tangent = tangent_flow(root, normal, groom["flow"], radius)
    angle = np.radians(groom["rest_angle_deg"])
    rest = np.cos(angle) * tangent + np.sin(angle) * normal
    length = groom["length"] * (1.0 - groom["length_jitter"] * rng.random(count))
    multiplier = rng.uniform(-1.0, 1.0, count)
    shape = arc_shapes(length, groom["points"], np.radians(groom["bend_deg"]))
    return Guides(root, normal, rest, side_vectors(normal, rest), length, multiplier, shape)


def closest_surface_point(
    points: np.ndarray, radius: float, height: float
) -> tuple[np.ndarray, np.ndarray]:
    """Nearest points on the mantle's surface (wall or caps) and their normals."""
    half = 0.5 * height
    rho = np.linalg.norm(points[:, :2], axis=1)
    ring = np.where(rho[:, None] > 1e-12, points[:, :2] / np.maximum(rho, 1e-12)[:, None], (1, 0))
    wall = np.column_stack([radius * ring, np.clip(points[:, 2], -half, half)])
    inside = np.minimum(rho, radius)[:, None] * ring
    top = np.column_stack([inside, np.full(len(points), half)])
    bottom = np.column_stack([inside, np.full(len(points), -half)])
    candidates = np.stack([wall, top, bottom])
    normals = np.stack(
        [
            np.column_stack([ring, np.zeros(len(points))]),
            np.tile((0.0, 0.0, 1.0), (len(points), 1)),
            np.tile((0.0, 0.0, -1.0), (len(points), 1)),
        ]
    )
    best = np.argmin(np.linalg.norm(candidates - points[None], axis=2), axis=0)
    rows = np.arange(len(points))
    return candidates[best, rows], normals[best, rows]


def resample(polyline: np.ndarray, points: int) -> np.ndarray:
    """`points` points evenly spaced by arc length along `polyline` (k, 3)."""
    steps = np.linalg.norm(np.diff(polyline, axis=0), axis=1)
    along = np.concatenate([[0.0], np.cumsum(steps)])
    where = np.linspace(0.0, along[-1], points)
    return np.column_stack([np.interp(where, along, polyline[:, i]) for i in range(3)])


def explicit(guides: list[dict[str, Any]], points: int, radius: float, height: float) -> Guides:
    """Guides listed as polylines in the creature frame; roots snapped to the skin."""
    curves = [resample(np.asarray(g["points"], dtype=np.float64), points) for g in guides]
    stack = np.array(curves).reshape(len(curves), points, 3)
    root, normal = closest_surface_point(stack[:, 0], radius, height)
    local = stack - stack[:, :1]  # the curve moves with its root onto the skin
    rest = _unit(local[:, 1])
    side = side_vectors(normal, rest)
    up = np.cross(rest, side)
    frame = np.stack([rest, up, side], axis=1)  # (n, 3 axes, 3)
    shape = np.einsum("npk,nak->npa", local, frame)
    length = np.sum(np.linalg.norm(np.diff(stack, axis=1), axis=2), axis=1)
    multiplier = np.zeros(len(guides))
    return Guides(root + 0.0, normal, rest, side, length, multiplier, shape)
