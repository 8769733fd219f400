"""The REDUCED tier's body (`physics.reduced` maps its states to the full model's).

Per morphology (one `Batch`), the reduced creature is built from the full one
(`reduced_spec`): each tentacle's links are joined in consecutive groups (`groups`:
about half as many links, at least 3, or all of them when there are fewer), a group
becoming one capsule as long as its links together, as heavy, as thick on average,
bending as far as they do together. Its geoms touch the ground
and the contact proxies (other creatures) as the full ones do: with ground contact at
the tips alone the creature stands on its mantle, 2.5 cm lower than a full one (a pop
at every tier move), for 13 % less cost. Its suckers hang from the links that hold
theirs, at the same places.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import mujoco
import numpy as np

from ecs_tentacles.components import Creature, Link, Motor, Sucker, Tentacle
from ecs_tentacles.physics.model import (
    REDUCED_PROXY_MARGIN,
    add_link,
    add_mantle,
    add_proxies,
    add_sucker,
    new_spec,
)

if TYPE_CHECKING:
    from ecs_tentacles.physics.host import PhysicsHost

# The reduced links per full link (`groups`; at least 3). Halving the links is what sets
# a reduced creature's pace apart from its full self's: the per-creature progress ratio
# has an sd of 0.089 at 120 Hz and 0.098 at 480 Hz, 0.045 with every link kept at 120 Hz
# and 0.009 (the floor) with every link at 480 Hz (128 creatures, `tools/reduced_pace.py
# --model`, docs/crowds.md).
LINK_SHARE = 0.5
AXES = ("curl", "sweep", "twist")


def groups(links: int) -> list[np.ndarray]:
    """The full links (indices) each reduced link of a `links`-link tentacle stands for."""
    count = links if links <= 3 else max(3, math.ceil(links * LINK_SHARE))
    return np.array_split(np.arange(links), count)


@dataclass(frozen=True)
class Chain:
    """One tentacle as the reduced model sees it: full link lengths and the groups."""

    tentacle: int
    lengths: np.ndarray  # full links
    groups: list[np.ndarray]
    axes: tuple[str, ...]  # hinge axes of the full links (the reduced ones have the same)

    @property
    def reduced_lengths(self) -> np.ndarray:
        return np.array([self.lengths[g].sum() for g in self.groups])


def reduced_spec(world: PhysicsHost, creature: Creature, timestep: float) -> mujoco.MjSpec:
    """An MjSpec of `creature`'s reduced model (module docstring), mantle at the origin."""
    spec = new_spec(world, timestep)
    mantle = add_mantle(spec, creature)
    equalities = 0
    for tentacle_entity in creature.tentacles:
        tentacle = world.component(tentacle_entity, Tentacle)
        links = [world.component(e, Link) for e in tentacle.links]
        motors = [world.component(e, Motor) for e in tentacle.links]
        parts = groups(len(links))
        twist = all(lk.twist for lk in links)  # a twist hinge where every link has one
        parent: mujoco.MjsBody = mantle
        previous: float | None = None
        centres = []  # each reduced link's centre along the tentacle
        arc = 0.0
        for k, group in enumerate(parts):
            joined = _joined([links[i] for i in group], twist)
            prefix = f"t{tentacle.index}/l{k:02d}"
            motor = motors[int(group[0])]
            body = add_link(
                spec, parent, creature, tentacle.base_angle, prefix, joined, motor, previous
            )
            centres.append(arc + 0.5 * joined.length)
            arc += joined.length
            parent, previous = body, joined.length
        full_centres = np.cumsum([0.0] + [lk.length for lk in links])[:-1]
        full_centres += 0.5 * np.array([lk.length for lk in links])
        for sucker_entity in tentacle.suckers:
            sucker = world.component(sucker_entity, Sucker)
            i = tentacle.links.index(sucker.link)
            k = next(k for k, g in enumerate(parts) if i in g)
            offset = np.asarray(sucker.offset) + [full_centres[i] - centres[k], 0.0, 0.0]
            add_sucker(spec, world, tentacle.index, equalities, k, offset)
            equalities += 1
    add_proxies(spec, margin=REDUCED_PROXY_MARGIN)
    return spec


def _joined(links: list[Link], twist: bool) -> Link:
    """One link standing for `links` end to end: as long and as heavy, as thick on
    average, bending as far."""
    length = sum(lk.length for lk in links)
    radius = sum(lk.radius * lk.length for lk in links) / length
    mass = sum(lk.density * _capsule_volume(lk.radius, lk.length) for lk in links)
    first = links[0]
    return Link(
        tentacle=first.tentacle,
        index=first.index,
        length=length,
        radius=radius,
        scale=first.scale,
        density=mass / _capsule_volume(radius, length),
        joint_limit=min(float(np.pi), sum(lk.joint_limit for lk in links)),
        twist=twist,
    )


def _capsule_volume(radius: float, length: float) -> float:
    return float(np.pi * radius**2 * length + 4.0 / 3.0 * np.pi * radius**3)


def chains(world: PhysicsHost, creature: Creature) -> list[Chain]:
    """`creature`'s tentacles as `ReducedModel` needs them."""
    out = []
    for tentacle_entity in creature.tentacles:
        tentacle = world.component(tentacle_entity, Tentacle)
        links = [world.component(e, Link) for e in tentacle.links]
        axes = AXES if all(lk.twist for lk in links) else AXES[:2]
        out.append(
            Chain(tentacle.index, np.array([lk.length for lk in links]), groups(len(links)), axes)
        )
    return out
