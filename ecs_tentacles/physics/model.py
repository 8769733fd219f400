"""Entities -> a MuJoCo model built in code with `mujoco.MjSpec`.

* mantle: a body with a free joint and a cylinder geom (height along +z);
* link: a body with a capsule geom along its local +x; its joint to the parent (the
  mantle or the previous link) is the thesis's motorised spherical joint, realised
  as hinges at the link's base: curl (about local +y; positive bends the tip down),
  sweep (about local +z; positive swings counter-clockwise) and optional twist
  (about local +x), each driven by a position servo (kp = strength, kv = damping);
* sucker: an inactive `connect` equality between its link and the world;
* ground: an infinite plane. Creatures touch the ground and each other, never
  themselves: creature k's geoms carry collision bit 1 + k % 30 and accept every
  creature bit but their own (creatures 30 apart in a scene therefore pass through
  each other).

Every element gets a stable name (`octo/t3/l07/curl`); `ModelNames` lists them per
store row so the backend can look ids up once after compiling.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import mujoco
import numpy as np

from ecs_tentacles.components import Creature, Link, Motor, Sucker, Tentacle, Transform
from ecs_tentacles.mathutil import quat_about_z

if TYPE_CHECKING:
    from ecs_tentacles.world import World

AXES = {"curl": (0.0, 1.0, 0.0), "sweep": (0.0, 0.0, 1.0), "twist": (1.0, 0.0, 0.0)}
AXIS_INDEX = {"curl": 0, "sweep": 1, "twist": 2}
JOINT_ARMATURE = 0.002
GROUND_BIT = 1
CREATURE_BITS = 30
ALL_CREATURES = ((1 << CREATURE_BITS) - 1) << 1


def collision_bits(index: int) -> tuple[int, int]:
    """(contype, conaffinity) of creature `index`: touches the ground and other creatures."""
    own = 1 << (1 + index % CREATURE_BITS)
    return own, GROUND_BIT | (ALL_CREATURES & ~own)


# MuJoCo takes the larger friction of two touching geoms: creature skin is zero so the
# scene's ground_friction alone sets how creatures slide.
SKIN_FRICTION = [0.0, 0.0, 0.0]
# Stiffer contacts than MuJoCo's default (0.02 s), so thin tips do not sink into the
# ground; still above twice the default timestep (1 / 480 s).
CONTACT_SOLREF = [0.006, 1.0]
# Suckers hold harder than contacts push (impedance close to 1): the tip stays put.
SUCKER_SOLIMP = [0.97, 0.995, 0.001, 0.5, 2.0]


@dataclass
class ModelNames:
    """Names of the MuJoCo elements, in store-row order."""

    bodies: list[str] = field(default_factory=list)  # per transform row
    actuators: list[str] = field(default_factory=list)  # one per hinge
    actuator_motor_rows: list[int] = field(default_factory=list)
    actuator_axes: list[int] = field(default_factory=list)
    equalities: list[str] = field(default_factory=list)  # per sucker row
    mantle_joints: list[str] = field(default_factory=list)


def build_spec(world: World) -> tuple[mujoco.MjSpec, ModelNames]:
    """An MjSpec of the whole scene and the names of its elements by store row."""
    settings = world.settings
    spec = mujoco.MjSpec()
    spec.modelname = "ecs_tentacles"
    spec.compiler.degree = False  # joint ranges are radians
    spec.option.timestep = settings.substep_dt
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    spec.option.gravity = list(settings.gravity)
    spec.worldbody.add_geom(
        name="ground",
        type=mujoco.mjtGeom.mjGEOM_PLANE,
        size=[0.0, 0.0, 1.0],
        friction=[settings.ground_friction, 0.005, 0.0001],
        contype=GROUND_BIT,
        conaffinity=ALL_CREATURES,
        solref=CONTACT_SOLREF,
    )
    names = ModelNames(bodies=[""] * len(world.transforms))
    for index, (_, (creature, transform)) in enumerate(sorted(world.query(Creature, Transform))):
        _add_creature(spec, world, creature, transform, names, collision_bits(index))
    if any(not name for name in names.bodies):
        raise RuntimeError("a Transform row has no body: build entities with ecs_tentacles.build")
    return spec, names


def _add_creature(
    spec: mujoco.MjSpec,
    world: World,
    creature: Creature,
    transform: Transform,
    names: ModelNames,
    bits: tuple[int, int],
) -> None:
    mantle = spec.worldbody.add_body(
        name=f"{creature.name}/mantle", pos=transform.pos, quat=transform.quat
    )
    mantle.add_freejoint(name=f"{creature.name}/root")
    mantle.add_geom(
        name=f"{creature.name}/mantle",
        type=mujoco.mjtGeom.mjGEOM_CYLINDER,
        size=[creature.mantle_radius, 0.5 * creature.mantle_height, 0.0],
        density=creature.mantle_density,
        contype=bits[0],
        conaffinity=bits[1],
        friction=SKIN_FRICTION,
        solref=CONTACT_SOLREF,
    )
    names.bodies[transform.row] = mantle.name
    names.mantle_joints.append(f"{creature.name}/root")
    for tentacle_entity in creature.tentacles:
        tentacle = world.component(tentacle_entity, Tentacle)
        parent = mantle
        previous: Link | None = None
        for link_entity in tentacle.links:
            link = world.component(link_entity, Link)
            prefix = f"{creature.name}/t{tentacle.index}/l{link.index:02d}"
            if previous is None:  # base of the tentacle: edge of the mantle's base
                angle = tentacle.base_angle
                distance = creature.mantle_radius + 0.5 * link.length
                pos = [
                    distance * np.cos(angle),
                    distance * np.sin(angle),
                    -0.5 * creature.mantle_height,
                ]
                quat = quat_about_z(angle)
            else:
                pos = [0.5 * (previous.length + link.length), 0.0, 0.0]
                quat = np.array([1.0, 0.0, 0.0, 0.0])
            body = parent.add_body(name=prefix, pos=pos, quat=quat)
            body.add_geom(
                name=prefix,
                type=mujoco.mjtGeom.mjGEOM_CAPSULE,
                fromto=[-0.5 * link.length, 0, 0, 0.5 * link.length, 0, 0],
                size=[link.radius, 0.0, 0.0],
                density=link.density,
                contype=bits[0],
                conaffinity=bits[1],
                friction=SKIN_FRICTION,
                solref=CONTACT_SOLREF,
            )
            names.bodies[world.component(link_entity, Transform).row] = prefix
            motor = world.component(link_entity, Motor)
            hinges = ("curl", "sweep", "twist") if link.twist else ("curl", "sweep")
            for hinge in hinges:
                _add_servo(spec, body, f"{prefix}/{hinge}", hinge, link, motor, names)
            parent, previous = body, link
        for sucker_entity in tentacle.suckers:
            sucker = world.component(sucker_entity, Sucker)
            name = f"{creature.name}/t{tentacle.index}/sucker{len(names.equalities)}"
            equality = spec.add_equality(
                name=name,
                type=mujoco.mjtEq.mjEQ_CONNECT,
                objtype=mujoco.mjtObj.mjOBJ_BODY,
                name1=names.bodies[sucker.link_row],
                name2="world",
                active=False,
                solref=[world.settings.sucker_timeconst, 1.0],
                solimp=SUCKER_SOLIMP,
            )
            data = np.array(equality.data)
            data[0:3] = sucker.offset  # anchor in the link frame; the world anchor is set at attach
            equality.data = data
            names.equalities.append(name)


def _add_servo(
    spec: mujoco.MjSpec,
    body: mujoco.MjsBody,
    name: str,
    hinge: str,
    link: Link,
    motor: Motor,
    names: ModelNames,
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
    names.actuators.append(name)
    names.actuator_motor_rows.append(motor.row)
    names.actuator_axes.append(AXIS_INDEX[hinge])
