"""One creature's entities -> a MuJoCo model built in code with `mujoco.MjSpec`.

Every creature has its own model (its state a row of a batch, `physics.batch`): a model
holding that creature alone, built at the origin and placed by its free joint, so
creatures of one morphology share one compiled model (`model_layout(...).key` says which
ones match; the backend compiles each key once and copies the compiled model).

* mantle: a body with a free joint and a cylinder geom (height along +z);
* link: a body with a capsule geom along its local +x; its joint to the parent (the
  mantle or the previous link) is the thesis's motorised spherical joint, realised
  as hinges at the link's base: curl (about local +y; positive bends the tip down),
  sweep (about local +z; positive swings counter-clockwise) and optional twist
  (about local +x), each driven by a position servo (kp = strength, kv = damping);
* sucker: an inactive `connect` equality between its link and the world;
* ground: an infinite plane;
* contact proxies: a pool of kinematic (mocap) capsules and cylinders that the
  backend places where other creatures' bodies are, so creatures in different
  models push each other (`ecs_tentacles.physics.proxies`). A creature touches the
  ground and the proxies, never itself; proxies touch only the creature.

Element names are the same in every creature's model (`t3/l07/curl`); `ModelLayout`
lists, in model order, which store rows they belong to.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, NamedTuple

import mujoco
import numpy as np

from ecs_tentacles.components import Creature, Link, Motor, Sucker, Tentacle, Transform
from ecs_tentacles.ground import FLAT, StaticContact, StaticSpec
from ecs_tentacles.numeric.quaternions import quat_about_z
from ecs_tentacles.registry import Registry

if TYPE_CHECKING:
    from ecs_tentacles.physics.host import PhysicsHost
    from ecs_tentacles.settings import Settings

AXES = {"curl": (0.0, 1.0, 0.0), "sweep": (0.0, 0.0, 1.0), "twist": (1.0, 0.0, 0.0)}
AXIS_INDEX = {"curl": 0, "sweep": 1, "twist": 2}
JOINT_ARMATURE = 0.002
GROUND_BIT, CREATURE_BIT, PROXY_BIT = 1, 2, 4
# Proxy pool per model: enough capsules for the nearest links of the creatures around
# (the nearest are chosen when more are near), a few cylinders for their mantles.
PROXY_CAPSULES = 64
PROXY_CYLINDERS = 4
PROXY_PARK = np.array([1.0e4, 0.0, -1.0e4])  # unused proxies wait here, 10 m apart
PROXY_SLOTS = PROXY_CAPSULES + PROXY_CYLINDERS
PROXY_PARKED = PROXY_PARK + np.outer(np.arange(PROXY_SLOTS) * 10.0, [1.0, 0.0, 0.0])  # per slot

# Each stepping thread has one MjData per model (physics/batch.py), never one per
# creature, so the arena can hold the schema's largest creature (16 x 64 links needs more
# than 4 MB at rest); pages it never touches are not resident.
ARENA_BYTES = 64 << 20

# MuJoCo takes the larger friction of two touching geoms: creature skin is zero so the
# scene's ground_friction alone sets how creatures slide.
SKIN_FRICTION = [0.0, 0.0, 0.0]
# Stiffer contacts than MuJoCo's default (0.02 s), so thin tips do not sink into the
# ground; still above twice the default timestep (1 / 480 s).
CONTACT_SOLREF = [0.006, 1.0]
# Contacts with proxies (other creatures' bodies, placed once a frame). A proxy stands
# still for the frame while the body it stands for moves on, so its contact starts
# PROXY_MARGIN early and is as stiff as the step allows (timeconst 2 substeps, high
# impedance); measured on crowds, creatures then never interpenetrate by more than a
# few mm (docs/crowds.md).
PROXY_SOLREF = [0.004, 1.0]
PROXY_SOLIMP = [0.95, 0.99, 0.002, 0.5, 2.0]
PROXY_MARGIN = 0.008
# The reduced tier steps once a frame (1 / 60 s), where MuJoCo keeps a contact's time
# constant at two steps (33 ms): soft enough that two reduced creatures driven head on
# (crowd avoidance off) went 25-31 mm into each other with the full tier's margin (5-15
# mm at 120 Hz). Its proxies push from REDUCED_PROXY_MARGIN away instead.
REDUCED_PROXY_MARGIN = 0.03
# Suckers hold harder than contacts push (impedance close to 1): the tip stays put.
SUCKER_SOLIMP = [0.97, 0.995, 0.001, 0.5, 2.0]


@dataclass
class ModelLayout:
    """Which store rows a creature model's elements belong to, in model-building order."""

    key: tuple[object, ...]  # the morphology: equal keys compile to equal models
    body_rows: list[int] = field(default_factory=list)  # transform row per body name
    bodies: list[str] = field(default_factory=list)
    actuators: list[str] = field(default_factory=list)  # one per hinge
    actuator_motor_rows: list[int] = field(default_factory=list)
    actuator_axes: list[int] = field(default_factory=list)
    equalities: list[str] = field(default_factory=list)  # one per sucker
    sucker_rows: list[int] = field(default_factory=list)


def model_layout(world: PhysicsHost, creature: Creature, transform: Transform) -> ModelLayout:
    """The creature model's morphology key and its elements' store rows, building nothing.

    A tentacle's links are the consecutive rows of the Transform and Motor stores from its
    `base_row` and `first_link` (`TentacleStore`), so those rows are read from the
    tentacle's; element names are made once per tentacle shape (`_tentacle_names`).
    """
    key: list[object] = [
        _settings_key(world.settings),
        (creature.mantle_radius, creature.mantle_height, creature.mantle_density),
    ]
    layout = ModelLayout(key=())
    layout.bodies.append("mantle")
    layout.body_rows.append(transform.row)
    tentacles, sucker_offsets = world.tentacles, world.suckers.offset
    for tentacle_entity in creature.tentacles:
        tentacle = world.component(tentacle_entity, Tentacle)
        links = [world.component(entity, Link) for entity in tentacle.links]
        names = _tentacle_names(tentacle.index, tuple((lk.index, bool(lk.twist)) for lk in links))
        row = tentacle.row
        base, first = int(tentacles.base_row[row]), int(tentacles.first_link[row])
        layout.bodies += names.bodies
        layout.body_rows += range(base, base + len(links))
        layout.actuators += names.actuators
        layout.actuator_motor_rows += [first + i for i in names.actuator_links]
        layout.actuator_axes += names.actuator_axes
        index_of = {entity: i for i, entity in enumerate(tentacle.links)}
        found = [world.component(entity, Sucker) for entity in tentacle.suckers]
        rows = [sucker.row for sucker in found]
        offsets = sucker_offsets[rows].tolist()
        suckers: list[tuple[object, ...]] = []
        for sucker, sucker_row, offset in zip(found, rows, offsets, strict=True):
            layout.equalities.append(f"t{tentacle.index}/sucker{len(layout.equalities)}")
            layout.sucker_rows.append(sucker_row)
            suckers.append((index_of[sucker.link], *offset))
        shape = tuple(
            (lk.length, lk.radius, lk.density, lk.joint_limit, lk.twist, lk.scale) for lk in links
        )
        key.append((tentacle.base_angle, shape, tuple(suckers)))
    layout.key = tuple(key)
    return layout


class TentacleNames(NamedTuple):
    """A tentacle's element names in model order, and each actuator's link and axis."""

    bodies: tuple[str, ...]
    actuators: tuple[str, ...]
    actuator_links: tuple[int, ...]  # the link (0 at the base) of each actuator
    actuator_axes: tuple[int, ...]  # `AXIS_INDEX` of each actuator's hinge


@functools.lru_cache(maxsize=1024)
def _tentacle_names(index: int, links: tuple[tuple[int, bool], ...]) -> TentacleNames:
    """The names of tentacle `index` whose links are `(link index, twist)`, base first."""
    bodies, actuators, actuator_links, axes = [], [], [], []
    for i, (link, twist) in enumerate(links):
        prefix = f"t{index}/l{link:02d}"
        bodies.append(prefix)
        for hinge in ("curl", "sweep", "twist") if twist else ("curl", "sweep"):
            actuators.append(f"{prefix}/{hinge}")
            actuator_links.append(i)
            axes.append(AXIS_INDEX[hinge])
    return TentacleNames(tuple(bodies), tuple(actuators), tuple(actuator_links), tuple(axes))


def _settings_key(settings: Settings) -> tuple[object, ...]:
    return (settings.substep_dt, tuple(settings.gravity), settings.ground_friction,
            settings.sucker_timeconst)  # fmt: skip


class StaticGeometry(Registry[Callable[[StaticSpec, StaticContact], None]]):
    """Static geoms in every creature's model, filled in plugins' `build(app)`: an entry
    `(spec, contact)` adds them to a creature's MjSpec (their friction, contact bits and
    solref from `contact`, a `ground.StaticContact`), named `ground...` (the terrain
    plugin: its heightfield, the plane beyond it, its solids). Without an entry the model
    has the plane z = 0 (`ground.FLAT`)."""


def hinges(link: Link) -> tuple[str, ...]:
    return ("curl", "sweep", "twist") if link.twist else ("curl", "sweep")


def build_spec(
    world: PhysicsHost, creature: Creature, timestep: float | None = None
) -> mujoco.MjSpec:
    """An MjSpec of `creature` alone, its mantle at the origin, with the proxy pool.

    `timestep` (default: the scene's substep) gives a cheaper model of the same
    creature (the REDUCED level of detail, `physics.tiers`).
    """
    spec = new_spec(world, timestep)
    _add_creature(spec, world, creature)
    add_proxies(spec)
    return spec


def new_spec(world: PhysicsHost, timestep: float | None = None) -> mujoco.MjSpec:
    """An MjSpec with the scene's options (`timestep`, default the scene's substep) and
    its ground, before any creature is added."""
    settings = world.settings
    spec = mujoco.MjSpec()
    spec.modelname = "ecs_tentacles_creature"
    spec.compiler.degree = False  # joint ranges are radians
    spec.option.timestep = settings.substep_dt if timestep is None else timestep
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    spec.option.gravity = list(settings.gravity)
    # The framework, not MuJoCo, decides what happens after a blow-up (physics/health.py).
    spec.option.disableflags |= mujoco.mjtDisableBit.mjDSBL_AUTORESET
    # One arena per stepping thread and model (ARENA_BYTES). A blow-up that overflows it
    # is caught as a fatal error and recovered (physics/health.py).
    spec.memory = ARENA_BYTES
    # the static geometry plugins add (a heightfield, solids), else the plane z = 0
    statics = list(world.registry(StaticGeometry))
    contact = StaticContact(settings.ground_friction, GROUND_BIT, CREATURE_BIT, CONTACT_SOLREF)
    for add in statics or [FLAT.add_to_spec]:
        add(spec, contact)
    return spec


SKIN = {
    "contype": CREATURE_BIT,
    "conaffinity": GROUND_BIT | PROXY_BIT,
    "friction": SKIN_FRICTION,
    "solref": CONTACT_SOLREF,
}  # a creature's geoms touch the ground and the proxies, never each other


def add_mantle(spec: mujoco.MjSpec, creature: Creature) -> mujoco.MjsBody:
    """The mantle body: a free joint and a cylinder, at the origin."""
    mantle = spec.worldbody.add_body(name="mantle")
    mantle.add_freejoint(name="root")
    mantle.add_geom(
        name="mantle",
        type=mujoco.mjtGeom.mjGEOM_CYLINDER,
        size=[creature.mantle_radius, 0.5 * creature.mantle_height, 0.0],
        density=creature.mantle_density,
        **SKIN,
    )
    return mantle


def add_link(
    spec: mujoco.MjSpec,
    parent: mujoco.MjsBody,
    creature: Creature,
    base_angle: float,
    prefix: str,
    link: Link,
    motor: Motor,
    previous: float | None,
) -> mujoco.MjsBody:
    """Link body `prefix` (capsule and servos) on `parent`: at the mantle's base edge at
    `base_angle` when `previous` (the parent link's length) is None, else end to end."""
    if previous is None:  # base of the tentacle: edge of the mantle's base
        distance = creature.mantle_radius + 0.5 * link.length
        pos = [
            distance * np.cos(base_angle),
            distance * np.sin(base_angle),
            -0.5 * creature.mantle_height,
        ]
        quat = quat_about_z(base_angle)
    else:
        pos = [0.5 * (previous + link.length), 0.0, 0.0]
        quat = np.array([1.0, 0.0, 0.0, 0.0])
    body = parent.add_body(name=prefix, pos=pos, quat=quat)
    body.add_geom(
        name=prefix,
        type=mujoco.mjtGeom.mjGEOM_CAPSULE,
        fromto=[-0.5 * link.length, 0, 0, 0.5 * link.length, 0, 0],
        size=[link.radius, 0.0, 0.0],
        density=link.density,
        **SKIN,
    )
    for hinge in hinges(link):
        add_servo(spec, body, f"{prefix}/{hinge}", hinge, link, motor)
    return body


def _add_creature(spec: mujoco.MjSpec, world: PhysicsHost, creature: Creature) -> None:
    mantle = add_mantle(spec, creature)
    equalities = 0
    for tentacle_entity in creature.tentacles:
        tentacle = world.component(tentacle_entity, Tentacle)
        parent = mantle
        previous: Link | None = None
        for link_entity in tentacle.links:
            link = world.component(link_entity, Link)
            prefix = f"t{tentacle.index}/l{link.index:02d}"
            motor = world.component(link_entity, Motor)
            length = None if previous is None else previous.length
            body = add_link(
                spec, parent, creature, tentacle.base_angle, prefix, link, motor, length
            )
            parent, previous = body, link
        for sucker_entity in tentacle.suckers:
            sucker = world.component(sucker_entity, Sucker)
            link_index = tentacle.links.index(sucker.link)
            add_sucker(spec, world, tentacle.index, equalities, link_index, sucker.offset)
            equalities += 1


def add_sucker(
    spec: mujoco.MjSpec,
    world: PhysicsHost,
    tentacle: int,
    number: int,
    link: int,
    offset: object,
) -> None:
    """Sucker equality `number`: link `link` of tentacle `tentacle` held to the world at
    `offset` in the link's frame (off until it attaches; the world anchor is set then)."""
    equality = spec.add_equality(
        name=f"t{tentacle}/sucker{number}",
        type=mujoco.mjtEq.mjEQ_CONNECT,
        objtype=mujoco.mjtObj.mjOBJ_BODY,
        name1=f"t{tentacle}/l{link:02d}",
        name2="world",
        active=False,
        solref=[world.settings.sucker_timeconst, 1.0],
        solimp=SUCKER_SOLIMP,
    )
    data = np.array(equality.data)
    data[0:3] = offset
    equality.data = data


def add_proxies(spec: mujoco.MjSpec, margin: float = PROXY_MARGIN) -> None:
    """Kinematic stand-ins for other creatures' bodies; sized and placed per frame; their
    contacts start `margin` before the geoms touch."""
    z_to_x = [np.sqrt(0.5), 0.0, np.sqrt(0.5), 0.0]  # capsules lie along +x like links
    kinds = (
        ("capsule", PROXY_CAPSULES, mujoco.mjtGeom.mjGEOM_CAPSULE, z_to_x),
        ("cylinder", PROXY_CYLINDERS, mujoco.mjtGeom.mjGEOM_CYLINDER, [1.0, 0.0, 0.0, 0.0]),
    )
    slot = 0
    for kind, count, geom_type, quat in kinds:
        for i in range(count):
            body = spec.worldbody.add_body(
                name=f"proxy/{kind}{i}", mocap=True, pos=PROXY_PARKED[slot]
            )
            body.add_geom(
                name=f"proxy/{kind}{i}",
                type=geom_type,
                size=[0.01, 0.01, 0.0],
                quat=quat,
                contype=PROXY_BIT,
                conaffinity=CREATURE_BIT,
                condim=1,  # frictionless: a zero-friction pyramid is degenerate and blows up
                margin=margin,
                priority=1,  # its contact parameters win over the creature's
                solref=PROXY_SOLREF,
                solimp=PROXY_SOLIMP,
            )
            slot += 1


def add_servo(
    spec: mujoco.MjSpec, body: mujoco.MjsBody, name: str, hinge: str, link: Link, motor: Motor
) -> None:
    body.add_joint(
        name=name,
        type=mujoco.mjtJoint.mjJNT_HINGE,
        pos=[-0.5 * link.length, 0.0, 0.0],
        axis=AXES[hinge],
        range=[-link.joint_limit, link.joint_limit],
        limited=mujoco.mjtLimited.mjLIMITED_TRUE,
        armature=JOINT_ARMATURE * link.scale,
    )
    actuator = spec.add_actuator(name=name, target=name, trntype=mujoco.mjtTrn.mjTRN_JOINT)
    actuator.set_to_position(kp=motor.strength, kv=motor.damping)
    actuator.forcelimited = mujoco.mjtLimited.mjLIMITED_TRUE
    actuator.forcerange = [-motor.max_torque, motor.max_torque]
