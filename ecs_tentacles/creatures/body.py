"""Scene data -> a creature's body: the creature, its tentacles, links and suckers.

Takes a validated scene dict with defaults applied (`ecs_tentacles.scene.load`)
and creates the entities with their components and store rows, posed by the
construction rules (`ecs_tentacles.scene.construction`). Plugins then add what they own to
each creature (goals, action queues, fur: their `build_creature` hooks). Physics is
built afterwards, from these entities (`ecs_tentacles.physics.model`).
"""

from __future__ import annotations

import hashlib
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from ecs_tentacles.components import Creature, Link, Motor, Sucker, Tentacle, Transform
from ecs_tentacles.ground import ground_of
from ecs_tentacles.numeric.quaternions import quat_about_z
from ecs_tentacles.scene.construction import CreatureLayout, creature_layout
from ecs_tentacles.scene.parameters import apply_parameters, parameter

if TYPE_CHECKING:
    from ecs_tentacles.host import Host
    from ecs_tentacles.scene.spec import CreatureSpec


def creature_rng(seed: int, name: str) -> np.random.Generator:
    """The random stream of one creature: from the world's seed and the creature's name.

    Never from a stream shared by all creatures, so a creature draws the same values
    whichever creatures are built before it (a shard of a distributed bake builds only
    some of them), and adding or removing a creature leaves the others' draws alone.
    """
    key = int.from_bytes(hashlib.sha256(name.encode()).digest()[:8], "little")
    return np.random.default_rng([int(seed), key])


def build_creature(world: Host, spec: CreatureSpec, layout: CreatureLayout | None = None) -> int:
    """Create one creature's entities from its scene entry; return the creature entity.
    `layout`: the entry's `creature_layout` on this world's ground, when the caller has
    it already (a spawn checked the spot with it)."""
    mantle = spec["mantle"]
    tentacles = spec["tentacles"]
    if layout is None:
        layout = creature_layout(spec, ground_of(world))
    turn = quat_about_z(layout.heading)

    creature = Creature(
        name=spec["name"],
        mantle_radius=mantle["radius"],
        mantle_height=mantle["height"],
        mantle_density=mantle["density"],
    )
    centre = layout.origin + np.array([0.0, 0.0, 0.5 * mantle["height"]])
    row = int(world.transforms.add(pos=centre, quat=turn)[0])
    added = world.creatures.add(
        mantle_row=row,
        mantle_radius=mantle["radius"],
        first_tentacle=len(world.tentacles),
        tentacles=tentacles["count"],
    )
    creature.attach(world.creatures, int(added[0]))
    creature_entity = world.create_entity(creature, Transform(world.transforms, row))
    world.creatures.entity[creature.row] = creature_entity

    for k, angle in enumerate(layout.angles):
        tentacle = Tentacle(creature=creature_entity, index=k, base_angle=float(angle))
        tentacle_entity = world.create_entity(tentacle)
        creature.tentacles.append(tentacle_entity)
        rows = _build_links(world, tentacle, tentacle_entity, layout, k)
        _add_tentacle_row(world, tentacle, creature.row, layout, k, rows)
    return creature_entity


def _add_tentacle_row(
    world: Host,
    tentacle: Tentacle,
    creature_row: int,
    layout: CreatureLayout,
    k: int,
    rows: LinkRows,
) -> None:
    params, shape = layout.params[k], layout.shapes[k]
    added = world.tentacles.add(
        creature_row=creature_row,
        base_angle=tentacle.base_angle,
        first_link=rows.motors[0],
        links=len(rows.motors),
        base_row=rows.transforms[0],
        tip_sucker=rows.suckers[-1],
        length=shape.length,
        rest_pitch=shape.rest_pitch,
    )
    tentacle.attach(world.tentacles, int(added[0]))
    apply_parameters(world, "tentacles", params, {"tentacles": tentacle.row})
    world.motors.tentacle_row[rows.motors] = tentacle.row
    world.suckers.tentacle_row[rows.suckers] = tentacle.row


class LinkRows(NamedTuple):
    """The store rows of one tentacle's links (transforms, motors) and suckers, in order."""

    transforms: list[int]
    motors: list[int]
    suckers: list[int]


def _build_links(
    world: Host,
    tentacle: Tentacle,
    tentacle_entity: int,
    layout: CreatureLayout,
    k: int,
) -> LinkRows:
    params, shape = layout.params[k], layout.shapes[k]
    mantle_radius = layout.mantle_radius
    quat = quat_about_z(layout.heading + tentacle.base_angle)
    n = len(shape.scales)
    rows = world.transforms.add(n, pos=layout.link_centres(k), quat=quat)
    motor_rows = world.motors.add(
        n,
        arc=(shape.centres - mantle_radius)
        / (shape.centres[-1] + 0.5 * shape.lengths[-1] - mantle_radius),
        scale=shape.scales,
    )
    apply_parameters(world, "tentacles", params, {"motors": motor_rows})  # tapered by `scale`
    limit = float(parameter("tentacles", "joint_limit_deg").from_scene(params["joint_limit_deg"]))
    density, twist = params["density"], params["twist"]
    lengths, radii, scales = shape.lengths.tolist(), shape.radii.tolist(), shape.scales.tolist()
    transforms, motors = world.transforms, world.motors
    found = LinkRows(rows.tolist(), motor_rows.tolist(), [])
    for i, (row, motor_row) in enumerate(zip(found.transforms, found.motors, strict=True)):
        link = Link(tentacle_entity, i, lengths[i], radii[i], scales[i], density, limit, twist)
        entity = world.create_entity(link, Transform(transforms, row), Motor(motors, motor_row))
        tentacle.links.append(entity)
    carriers = np.arange(n) if params["suckers"] == "every_link" else np.array([n - 1])
    offsets = np.zeros((len(carriers), 3))  # on the link's underside, half way along
    offsets[:, 0] = 0.5 * shape.lengths[carriers]
    offsets[:, 2] = -shape.radii[carriers]
    sucker_rows = world.suckers.add(len(carriers), link_row=rows[carriers], offset=offsets)
    for i, sucker_row in zip(carriers.tolist(), sucker_rows.tolist(), strict=True):
        entity = world.create_entity(Sucker(world.suckers, sucker_row, tentacle.links[i]))
        world.suckers.entity[sucker_row] = entity
        tentacle.suckers.append(entity)
        found.suckers.append(sucker_row)
    return found
