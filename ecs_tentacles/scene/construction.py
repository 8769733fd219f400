"""Creature construction rules of the tentacle thesis (IV.A), translated to z-up.

* The mantle is a cylinder with its height along +z.
* Tentacle k of N lies along +x rotated by 360 deg * k / N about +z (counter-clockwise
  seen from above), its base on the outside edge of the mantle's base.
* Link i of n has scale 1 - (i / (n - 1)) * (1 - end_scale); a one-link tentacle is
  the first link alone, at scale 1. Its length and radius are the first link's times
  its scale.
* The first link's centre lies mantle radius + 1/2 link length along the axis; each
  child's centre lies 1/2 (parent length + child length) beyond its parent's.
* A creature's scene entry places the centre of the mantle's base at `position`; a 2-d
  position rests the thickest first link on the ground. Tentacles are straight at build.

These functions are pure: numbers (or a creature's scene entry) in, numpy arrays out. The
build (`ecs_tentacles.creatures.body`) and the load-time physical checks
(`ecs_tentacles.scene.physical`) both place creatures with them.
"""

from __future__ import annotations

import functools
from collections.abc import Mapping
from dataclasses import dataclass, replace
from typing import cast

import numpy as np

from ecs_tentacles.ground import FLAT, Ground
from ecs_tentacles.scene.spec import CreatureSpec, TentacleSettings, TentaclesSpec, as_spec

# metres between a creature placed on terrain and the surface (it settles in the first
# steps); the plane needs none: its creatures start exactly resting
GROUND_CLEARANCE = 0.003


def link_scales(links: int, end_scale: float) -> np.ndarray:
    """Scale factor of each of `links` links, from 1 at the base to `end_scale` at the tip."""
    if links < 1:
        raise ValueError(f"a tentacle needs at least one link, got {links}")
    if not 0.0 < end_scale <= 1.0:
        raise ValueError(f"end_scale must be in (0, 1], got {end_scale}")
    if links == 1:
        return np.ones(1)
    i = np.arange(links, dtype=np.float64)
    return 1.0 - (i / (links - 1)) * (1.0 - end_scale)


def tentacle_angles(count: int) -> np.ndarray:
    """Base angle (radians about +z) of each of `count` tentacles, counter-clockwise from +x."""
    if count < 1:
        raise ValueError(f"a creature needs at least one tentacle, got {count}")
    return 2.0 * np.pi * np.arange(count) / count


@dataclass(frozen=True)
class TentacleShape:
    """Per-link numbers of one tentacle; `centres` are distances along its axis."""

    scales: np.ndarray
    lengths: np.ndarray
    radii: np.ndarray
    centres: np.ndarray

    @property
    def length(self) -> float:
        """Length of the whole tentacle along its axis."""
        return float(self.lengths.sum())

    @property
    def rest_pitch(self) -> float:
        """Tilt (radians) that lays the underside of the tapering tentacle on the ground.

        The axis drops by the base radius minus the tip radius over the tentacle's
        length. A tip so much thinner than the base that it cannot reach the ground
        even hanging straight down (a stub of fat, short links) gets pi / 2.
        """
        drop = float(self.radii[0] - self.radii[-1])
        return float(np.arcsin(min(1.0, drop / self.length)))


@functools.lru_cache(maxsize=4096)
def tentacle_shape(
    mantle_radius: float, link_length: float, link_radius: float, links: int, end_scale: float
) -> TentacleShape:
    """Lengths, radii and centre distances of a tentacle's links by the thesis's rules.

    Shared by every tentacle of the same numbers (a crowd's 80,000 tentacles have a few
    dozen shapes between them: working each out again was 4 % of building 10,000
    creatures), so its arrays are read-only."""
    scales = link_scales(links, end_scale)
    lengths = link_length * scales
    radii = link_radius * scales
    centres = np.empty(links)
    centres[0] = mantle_radius + 0.5 * lengths[0]
    centres[1:] = centres[0] + np.cumsum(0.5 * (lengths[:-1] + lengths[1:]))
    for array in (scales, lengths, radii, centres):
        array.flags.writeable = False
    return TentacleShape(scales=scales, lengths=lengths, radii=radii, centres=centres)


def tentacle_params(tentacles: Mapping[str, object], index: int) -> TentacleSettings:
    """The creature-wide tentacle settings with tentacle `index`'s overrides applied."""
    params = {key: tentacles[key] for key in tentacles if key != "overrides"}
    overrides = tentacles.get("overrides", [])
    for override in overrides if isinstance(overrides, list) else []:
        if override["index"] == index:
            params.update({k: v for k, v in override.items() if k != "index"})
    return cast(TentacleSettings, params)


def every_tentacle_params(tentacles: TentaclesSpec) -> list[TentacleSettings]:
    """`tentacle_params` of each tentacle; the tentacles no override names share one dict
    (a layout's `params` are read, never written: a crowd keeps one per creature)."""
    shared = tentacle_params(tentacles, -1)
    overridden = {override["index"] for override in tentacles.get("overrides", [])}
    return [
        tentacle_params(tentacles, k) if k in overridden else shared
        for k in range(tentacles["count"])
    ]


def resting_height(tentacles: TentaclesSpec) -> float:
    """Base height that lets the thickest first link rest on the ground."""
    return float(max(p["link_radius"] for p in every_tentacle_params(tentacles)))


@dataclass(frozen=True)
class CreatureLayout:
    """Where a creature's bodies are at build, from its scene entry (defaults filled in)."""

    origin: np.ndarray  # centre of the mantle's base, world frame
    heading: float  # radians about +z
    mantle_radius: float
    mantle_height: float
    angles: np.ndarray  # base angle of each tentacle in the creature frame
    params: list[TentacleSettings]  # each tentacle's settings, overrides applied (read only)
    shapes: list[TentacleShape]
    resting: bool = False  # placed by x, y alone: it rests on the ground under it

    def on(self, ground: Ground) -> CreatureLayout:
        """This layout (made on the plane) on `ground`: itself on the plane, or for a
        creature placed at x, y, z; else raised until its lowest point rests on the
        surface under it (plus `GROUND_CLEARANCE`)."""
        if not self.resting or ground.extent is None:
            return self
        lift = ground.lift(*_resting_points(self)) + GROUND_CLEARANCE
        return replace(self, origin=self.origin + [0.0, 0.0, lift])

    def axis(self, k: int) -> np.ndarray:
        """World-frame unit axis of tentacle `k`."""
        angle = self.heading + self.angles[k]
        return np.array([np.cos(angle), np.sin(angle), 0.0])

    def link_centres(self, k: int) -> np.ndarray:
        """World positions (links, 3) of tentacle `k`'s link centres."""
        return np.asarray(self.origin + self.shapes[k].centres[:, None] * self.axis(k))

    def capsules(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Every body as a capsule: segment starts (n, 3), ends (n, 3) and radii (n,).

        Row 0 is the mantle (its axis from base to top: exact sideways, rounded at the
        rims); the links follow, tentacle by tentacle, base to tip.
        """
        top = self.origin + np.array([0.0, 0.0, self.mantle_height])
        starts, ends, radii = [self.origin[None]], [top[None]], [np.array([self.mantle_radius])]
        for k, shape in enumerate(self.shapes):
            centres = self.link_centres(k)
            half = 0.5 * shape.lengths[:, None] * self.axis(k)
            starts.append(centres - half)
            ends.append(centres + half)
            radii.append(shape.radii)
        return np.concatenate(starts), np.concatenate(ends), np.concatenate(radii)


def creature_layout(spec: CreatureSpec, ground: Ground = FLAT) -> CreatureLayout:
    """The build-time layout of a creature from its scene entry (defaults filled in).

    A 2-d `position` rests the creature on `ground`: on the plane its thickest first
    link touches z = 0; on terrain the whole body is raised until its lowest point
    rests on the surface under it (plus `GROUND_CLEARANCE`; `CreatureLayout.on`). A
    load works each entry's out once (`ecs_tentacles.scene.layouts.Layouts`).
    """
    mantle, tentacles = spec["mantle"], spec["tentacles"]
    params = every_tentacle_params(tentacles)
    position = [float(v) for v in spec["position"]]
    if len(position) == 2:  # resting on the plane: the thickest first link touches it
        position.append(float(max(p["link_radius"] for p in params)))
    shapes = [
        tentacle_shape(
            mantle["radius"], p["link_length"], p["link_radius"], p["links"], p["end_scale"]
        )
        for p in params
    ]
    layout = CreatureLayout(
        origin=np.asarray(position, dtype=np.float64),
        heading=float(np.radians(spec["heading_deg"])),
        mantle_radius=float(mantle["radius"]),
        mantle_height=float(mantle["height"]),
        angles=tentacle_angles(tentacles["count"]),
        params=params,
        shapes=shapes,
        resting=len(spec["position"]) == 2,
    )
    return layout.on(ground)


def _resting_points(layout: CreatureLayout) -> tuple[np.ndarray, np.ndarray]:
    """Balls (centres (n, 3), radii (n,)) covering the body's underside: each link's ends
    and centre, and the rim and centre of the mantle's base."""
    starts, ends, radii = layout.capsules()
    rim = np.linspace(0.0, 2.0 * np.pi, 8, endpoint=False)
    base = layout.origin + layout.mantle_radius * np.stack(
        [np.cos(rim), np.sin(rim), np.zeros_like(rim)], axis=1
    )
    centres = np.concatenate([starts[1:], ends[1:], 0.5 * (starts[1:] + ends[1:]), base])
    balls = np.concatenate([radii[1:], radii[1:], radii[1:], np.zeros(len(base))])
    return np.vstack([centres, layout.origin]), np.append(balls, 0.0)


def capsule_mass_inertia(length: np.ndarray, radius: np.ndarray, density: float) -> np.ndarray:
    """(mass, smallest principal inertia) of capsules, the way MuJoCo computes them; (n, 2).

    The smallest principal inertia of a capsule is the one about its own axis.
    """
    cylinder = density * np.pi * radius**2 * length
    spheres = density * 4.0 / 3.0 * np.pi * radius**3
    axial = cylinder * radius**2 / 2.0 + spheres * 2.0 * radius**2 / 5.0
    return np.stack([cylinder + spheres, axial], axis=-1)


def cylinder_mass_inertia(radius: float, height: float, density: float) -> tuple[float, float]:
    """(mass, smallest principal inertia) of a solid cylinder such as the mantle."""
    mass = density * np.pi * radius**2 * height
    axial = mass * radius**2 / 2.0
    across = mass * (3.0 * radius**2 + height**2) / 12.0
    return float(mass), float(min(axial, across))


def creature_reach(creature: Mapping[str, object]) -> float:
    """Radius (m) of the circle around a creature's position that holds it at build.

    `creature` is a scene creature entry with its mantle radius and tentacle shape
    keys present (a `load_scene` result, or one the crowd generator made): the crowd
    generator and the shard planner space creatures by it.
    """
    spec = as_spec(creature)
    tentacles, radius = spec["tentacles"], spec["mantle"]["radius"]
    longest, thickest = 0.0, 0.0
    for k in range(tentacles["count"]):
        p = tentacle_params(tentacles, k)
        shape = tentacle_shape(
            radius, p["link_length"], p["link_radius"], p["links"], p["end_scale"]
        )
        longest = max(longest, float(shape.lengths.sum()))
        thickest = max(thickest, float(shape.radii.max()))
    return float(radius + longest + thickest)
