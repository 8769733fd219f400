"""Scene data -> a creature's body: the creature, its tentacles, links and suckers.

Takes a validated scene dict with defaults applied (`ecs_tentacles.scene.load`)
and creates the entities with their components and store rows, posed by the
construction rules (`ecs_tentacles.scene.construction`). Plugins then add what they own to
each creature (goals, action queues, fur: their `build_creature` hooks). Physics is
built afterwards, from these entities (`ecs_tentacles.physics.model`).
"""

from __future__ import annotations

import functools
import hashlib
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from ecs_tentacles.components import Creature, Link, Motor, Sucker, Tentacle, Transform
from ecs_tentacles.ground import ground_of
from ecs_tentacles.numeric.quaternions import quat_about_z
from ecs_tentacles.scene.construction import CreatureLayout, TentacleShape, creature_layout
from ecs_tentacles.scene.parameters import Parameter, apply_parameters, parameter

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

    rows = _add_rows(world, layout, creature.row)
    for k, angle in enumerate(layout.angles):
        tentacle = Tentacle(creature=creature_entity, index=k, base_angle=float(angle))
        tentacle_entity = world.create_entity(tentacle)
        creature.tentacles.append(tentacle_entity)
        _link_entities(world, tentacle, tentacle_entity, layout, k, rows[k])
        tentacle.attach(world.tentacles, rows[k].tentacle)
    return creature_entity


class LinkRows(NamedTuple):
    """The store rows of one tentacle: its links' (transforms, motors), its suckers' (on
    the links `carriers`) and its own."""

    transforms: np.ndarray
    motors: np.ndarray
    suckers: np.ndarray
    carriers: np.ndarray
    tentacle: int


def _add_rows(world: Host, layout: CreatureLayout, creature_row: int) -> list[LinkRows]:
    """Every tentacle's rows in each store, added at once per store (one `add` a store
    for the creature, not one a tentacle: the same rows in the same order), filled from
    the layout and the tentacles' parameters."""
    heading = layout.heading
    centres, quats, arcs, scales, carriers, offsets, counts = [], [], [], [], [], [], []
    for k, shape in enumerate(layout.shapes):
        every_link = layout.params[k]["suckers"] == "every_link"
        n, arc, on, offset = _shape_rows(shape, layout.mantle_radius, every_link)
        counts.append(n)
        centres.append(layout.link_centres(k))
        quats.append(quat_about_z(heading + float(layout.angles[k])))
        arcs.append(arc)
        scales.append(shape.scales)
        carriers.append(on)
        offsets.append(offset)
    total = sum(counts)
    transforms = world.transforms.add(
        total, pos=np.concatenate(centres), quat=np.repeat(quats, counts, axis=0)
    )
    motors = world.motors.add(total, arc=np.concatenate(arcs), scale=np.concatenate(scales))
    firsts = np.cumsum([0, *counts[:-1]])
    sucker_links = np.concatenate(
        [transforms[f + on] for f, on in zip(firsts, carriers, strict=True)]
    )
    suckers = world.suckers.add(
        len(sucker_links), link_row=sucker_links, offset=np.concatenate(offsets)
    )
    sucker_firsts = np.cumsum([0, *[len(on) for on in carriers[:-1]]])
    tips = sucker_firsts + [len(on) - 1 for on in carriers]
    tentacles = world.tentacles.add(
        len(counts),
        creature_row=creature_row,
        base_angle=layout.angles,
        first_link=motors[firsts],
        links=counts,
        base_row=transforms[firsts],
        tip_sucker=suckers[tips],
        length=[shape.length for shape in layout.shapes],
        rest_pitch=[shape.rest_pitch for shape in layout.shapes],
    )
    found = [
        LinkRows(
            transforms[first : first + n],
            motors[first : first + n],
            suckers[sucker_first : sucker_first + len(on)],
            on,
            int(tentacles[k]),
        )
        for k, (first, n, on, sucker_first) in enumerate(
            zip(firsts, counts, carriers, sucker_firsts, strict=True)
        )
    ]
    world.motors.tentacle_row[motors] = np.repeat(tentacles, counts)
    world.suckers.tentacle_row[suckers] = np.repeat(tentacles, [len(on) for on in carriers])
    # each parameter written once for the tentacles that share their settings (those no
    # override names share one dict: `every_tentacle_params`); links tapered by `scale`
    sharing: dict[int, list[int]] = {}
    for k, params in enumerate(layout.params):
        sharing.setdefault(id(params), []).append(k)
    for ks in sharing.values():
        link_rows = np.concatenate([found[k].motors for k in ks])
        rows = {"motors": link_rows, "tentacles": tentacles[ks]}
        apply_parameters(world, "tentacles", layout.params[ks[0]], rows)
    return found


@functools.cache
def _joint_limit() -> Parameter:
    """The `tentacles.joint_limit_deg` parameter (looked up once)."""
    return parameter("tentacles", "joint_limit_deg")


# (id(shape), mantle radius, suckers on every link) -> (shape kept alive, `_shape_rows`)
_SHAPE_ROWS: dict[tuple[int, float, bool], tuple[TentacleShape, ShapeRows]] = {}


class ShapeRows(NamedTuple):
    """What a tentacle's rows are filled with that its shape alone decides (read only)."""

    links: int
    arc: np.ndarray  # each link centre's place along the tentacle, 0 at the base, 1 at the tip
    carriers: np.ndarray  # the links with a sucker
    offsets: np.ndarray  # (carriers, 3): each sucker on its link's underside, half way along


def _shape_rows(shape: TentacleShape, mantle_radius: float, every_link: bool) -> ShapeRows:
    """`ShapeRows` of tentacles of `shape` on a mantle of `mantle_radius`, worked out once
    per shape (shapes are shared: `tentacle_shape`)."""
    key = (id(shape), mantle_radius, every_link)
    found = _SHAPE_ROWS.get(key)
    if found is not None and found[0] is shape:
        return found[1]
    n = len(shape.scales)
    reach = shape.centres[-1] + 0.5 * shape.lengths[-1] - mantle_radius
    on = np.arange(n) if every_link else np.array([n - 1])
    offsets = np.zeros((len(on), 3))
    offsets[:, 0] = 0.5 * shape.lengths[on]
    offsets[:, 2] = -shape.radii[on]
    rows = ShapeRows(n, (shape.centres - mantle_radius) / reach, on, offsets)
    for array in rows[1:]:
        array.flags.writeable = False
    if len(_SHAPE_ROWS) > 4096:
        _SHAPE_ROWS.clear()
    _SHAPE_ROWS[key] = (shape, rows)
    return rows


# id(shape) -> (shape kept alive, its links' lengths, radii and scales as Python floats)
_LINK_FLOATS: dict[int, tuple[TentacleShape, tuple[list[float], ...]]] = {}


def _link_floats(shape: TentacleShape) -> tuple[list[float], ...]:
    """`shape`'s link lengths, radii and scales as Python floats, made once per shape
    (read only): the `Link` components of every tentacle of that shape share them (a
    uniform crowd of 10,000 made 2.4 million floats of them, 58 MB)."""
    found = _LINK_FLOATS.get(id(shape))
    if found is not None and found[0] is shape:
        return found[1]
    floats = (shape.lengths.tolist(), shape.radii.tolist(), shape.scales.tolist())
    if len(_LINK_FLOATS) > 4096:
        _LINK_FLOATS.clear()
    _LINK_FLOATS[id(shape)] = (shape, floats)
    return floats


def _link_entities(
    world: Host,
    tentacle: Tentacle,
    tentacle_entity: int,
    layout: CreatureLayout,
    k: int,
    rows: LinkRows,
) -> None:
    """Tentacle `k`'s link and sucker entities, on their rows (`_add_rows`)."""
    params, shape = layout.params[k], layout.shapes[k]
    limit = float(_joint_limit().from_scene(params["joint_limit_deg"]))
    density, twist = params["density"], params["twist"]
    lengths, radii, scales = _link_floats(shape)
    transforms, motors = world.transforms, world.motors
    for i, (row, motor_row) in enumerate(
        zip(rows.transforms.tolist(), rows.motors.tolist(), strict=True)
    ):
        link = Link(tentacle_entity, i, lengths[i], radii[i], scales[i], density, limit, twist)
        entity = world.create_entity(link, Transform(transforms, row), Motor(motors, motor_row))
        tentacle.links.append(entity)
    for i, sucker_row in zip(rows.carriers.tolist(), rows.suckers.tolist(), strict=True):
        entity = world.create_entity(Sucker(world.suckers, sucker_row, tentacle.links[i]))
        world.suckers.entity[sucker_row] = entity
        tentacle.suckers.append(entity)
