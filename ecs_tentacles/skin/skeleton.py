"""A creature's joint skeleton and its animation, read from a take.

One joint per body, in the creature's hierarchy: the mantle is the root; each link's
parent is the previous link of its tentacle, the first link's parent the mantle.
A link's joint sits at the link's base (where MuJoCo's hinges are: local x = -L/2),
oriented like the link body; the mantle's joint is the mantle body itself.

Bind pose = the construction pose (`ecs_tentacles.scene.construction`: tentacle k straight
out along 360 deg * k / N about the mantle's +z, its base on the edge of the mantle's
base) placed at the mantle's frame-0 pose. A take's frame 0 is the pose the scene was
built in, so the bind pose is frame 0; tests check that they agree.

Animation: local joint rotations come from the simulated poses (parent^-1 * child);
the root translation is the mantle's position; link translations are constant (the
hinge point is fixed in the parent's frame), so only the root moves by translation.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from ecs_tentacles.numeric.quaternions import quat_about_z, quat_multiply, quat_rotate
from ecs_tentacles.scene.construction import tentacle_angles
from ecs_tentacles.take import Take


def quat_conjugate(q: np.ndarray) -> np.ndarray:
    """Inverse of unit quaternions (..., 4)."""
    inverse: np.ndarray = q * np.array([1.0, -1.0, -1.0, -1.0])
    return inverse


def quat_matrix(q: np.ndarray) -> np.ndarray:
    """(..., 4) unit (w, x, y, z) quaternions -> (..., 3, 3) rotation matrices."""
    w, x, y, z = np.moveaxis(np.asarray(q, dtype=np.float64), -1, 0)
    rows = [
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ]
    return np.stack([np.stack(row, axis=-1) for row in rows], axis=-2)


def transforms(rotation: np.ndarray, translation: np.ndarray) -> np.ndarray:
    """(..., 4, 4) affine matrices (column vectors) from quaternions and translations."""
    out = np.zeros((*rotation.shape[:-1], 4, 4))
    out[..., :3, :3] = quat_matrix(rotation)
    out[..., :3, 3] = translation
    out[..., 3, 3] = 1.0
    return out


@dataclass(frozen=True)
class TentacleLayout:
    """One tentacle in the bind pose: azimuth about the mantle's +z, per-link numbers."""

    angle: float
    lengths: np.ndarray  # (links,) spine length of each link (metres)
    radii: np.ndarray  # (links,)
    joints: np.ndarray  # (links,) skeleton joint index of each link


@dataclass(frozen=True)
class SkinLayout:
    """A creature as skinning needs it: mantle size and tentacles (mantle frame, metres)."""

    name: str
    mantle_radius: float
    mantle_height: float
    tentacles: list[TentacleLayout]


@dataclass(frozen=True)
class Skeleton:
    """Joints of one creature; index 0 is the mantle (root).

    `names` are USD-style joint paths (`mantle/t0_link0/t0_link1`), `parents` the
    parent index (-1 for the root), `bodies` the take body of each joint, `offset`
    the joint origin along the body's local x (-L/2 for links, 0 for the mantle).
    `rest_rotation`/`rest_translation` are the local bind transforms (parent frame),
    `bind` the world bind matrices (J, 4, 4).
    """

    layout: SkinLayout
    names: list[str]
    parents: np.ndarray
    bodies: np.ndarray
    offset: np.ndarray
    rest_rotation: np.ndarray
    rest_translation: np.ndarray
    bind: np.ndarray

    @property
    def leaf_names(self) -> list[str]:
        """The last path element of each joint (`mantle`, `t0_link3`)."""
        return [name.rsplit("/", 1)[-1] for name in self.names]


@dataclass(frozen=True)
class Animation:
    """Local joint transforms per frame: `rotation` (F, J, 4) w-first, `translation` (F, J, 3)."""

    times: np.ndarray
    rotation: np.ndarray
    translation: np.ndarray


def creature_skeleton(take: Take, creature: int) -> Skeleton:
    """The skeleton of creature number `creature` of `take`, bound at the construction pose
    placed at the mantle's frame-0 pose."""
    layout, body_index = creature_layout(take.header, creature)
    mantle = take.header["creatures"][creature]["mantle"]
    return build_skeleton(layout, body_index, take.quat[0, mantle], take.pos[0, mantle])


def creature_layout(header: Mapping[str, object], creature: int) -> tuple[SkinLayout, np.ndarray]:
    """Creature number `creature` of a take with this header: its layout (from the
    header's body sizes) and the take body of each joint (mantle, then link by link)."""
    creatures, bodies = header["creatures"], header["bodies"]
    assert isinstance(creatures, list) and isinstance(bodies, list)  # as `take.header` checks
    entry = creatures[creature]
    mantle = bodies[entry["mantle"]]
    chains = entry["tentacles"]
    tentacles = [
        (
            float(angle),
            [float(bodies[i]["length"]) for i in chain],
            [float(bodies[i]["radius"]) for i in chain],
        )
        for chain, angle in zip(chains, tentacle_angles(len(chains)), strict=True)
    ]
    layout = skin_layout(entry["name"], mantle["radius"], mantle["length"], tentacles)
    return layout, np.array([entry["mantle"], *(i for chain in chains for i in chain)])


def skin_layout(
    name: str,
    mantle_radius: float,
    mantle_height: float,
    tentacles: list[tuple[float, list[float], list[float]]],
) -> SkinLayout:
    """A layout from (azimuth, link lengths, link radii) per tentacle; joints numbered
    mantle first, then tentacle by tentacle, base to tip."""
    made, first = [], 1
    for angle, lengths, radii in tentacles:
        joints = np.arange(first, first + len(lengths))
        made.append(TentacleLayout(angle, np.array(lengths), np.array(radii), joints))
        first += len(lengths)
    return SkinLayout(name, float(mantle_radius), float(mantle_height), made)


def build_skeleton(
    layout: SkinLayout,
    bodies: np.ndarray,
    root_rotation: np.ndarray | None = None,
    root_translation: np.ndarray | None = None,
) -> Skeleton:
    """The skeleton of `layout` bound at its construction pose, the mantle at the given
    pose (the origin by default). `bodies` names the body (take index or store row) of
    each joint."""
    radius, height = layout.mantle_radius, layout.mantle_height
    names, parents, offset = ["mantle"], [-1], [0.0]
    rest_rotation = [np.array([1.0, 0.0, 0.0, 0.0])]
    rest_translation = [np.zeros(3)]
    for k, tentacle in enumerate(layout.tentacles):
        path, parent = "mantle", 0
        lengths, angle = tentacle.lengths, tentacle.angle
        for i in range(len(lengths)):
            path = f"{path}/t{k}_link{i}"
            names.append(path)
            parents.append(parent)
            offset.append(-0.5 * lengths[i])
            if i == 0:
                base = [radius * np.cos(angle), radius * np.sin(angle), -0.5 * height]
                rest_rotation.append(quat_about_z(angle))
                rest_translation.append(np.array(base))
            else:
                rest_rotation.append(np.array([1.0, 0.0, 0.0, 0.0]))
                rest_translation.append(np.array([lengths[i - 1], 0.0, 0.0]))
            parent = len(names) - 1
    rotation, translation = np.array(rest_rotation), np.array(rest_translation)
    if root_rotation is not None:
        rotation[0] = root_rotation
    if root_translation is not None:
        translation[0] = root_translation
    parent_array = np.array(parents)
    world_rotation, world_translation = forward(parent_array, rotation, translation)
    return Skeleton(
        layout=layout,
        names=names,
        parents=parent_array,
        bodies=np.asarray(bodies),
        offset=np.array(offset),
        rest_rotation=rotation,
        rest_translation=translation,
        bind=transforms(world_rotation, world_translation),
    )


def forward(
    parents: np.ndarray, rotation: np.ndarray, translation: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """World rotations and translations (..., J, 4) / (..., J, 3) from local ones.

    Parents come before children (as `creature_skeleton` orders them), so one pass over
    the joints composes every frame at once.
    """
    rotation = np.asarray(rotation, dtype=np.float64)
    world_r = np.empty_like(rotation)
    world_t = np.empty(rotation.shape[:-1] + (3,))
    for j, parent in enumerate(parents.tolist()):
        if parent < 0:
            world_r[..., j, :] = rotation[..., j, :]
            world_t[..., j, :] = translation[..., j, :]
        else:
            pr = world_r[..., parent, :]
            world_r[..., j, :] = quat_multiply(pr, rotation[..., j, :])
            world_t[..., j, :] = world_t[..., parent, :] + quat_rotate(pr, translation[..., j, :])
    return world_r, world_t


def joint_world_poses(skeleton: Skeleton, take: Take) -> tuple[np.ndarray, np.ndarray]:
    """Simulated world rotation (F, J, 4) and joint origin (F, J, 3) of every joint."""
    quat = take.quat[:, skeleton.bodies].astype(np.float64)
    quat /= np.linalg.norm(quat, axis=-1, keepdims=True)
    offset = np.zeros((len(skeleton.names), 3))
    offset[:, 0] = skeleton.offset
    return quat, take.pos[:, skeleton.bodies].astype(np.float64) + quat_rotate(quat, offset)


def creature_animation(skeleton: Skeleton, take: Take) -> Animation:
    """Local joint rotations from the simulated poses; the root translation from the mantle.

    Quaternion signs are made continuous along time (q and -q are the same rotation,
    but interpolating between them takes the long way round).
    """
    world, origin = joint_world_poses(skeleton, take)
    parents = skeleton.parents
    local = world.copy()
    children = np.flatnonzero(parents >= 0)
    local[:, children] = quat_multiply(
        quat_conjugate(world[:, parents[children]]), world[:, children]
    )
    flips = np.einsum("fjc,fjc->fj", local[1:], local[:-1]) < 0
    sign = np.ones(local.shape[:2])
    sign[1:] = np.where(np.cumsum(flips, axis=0) % 2 == 1, -1.0, 1.0)
    local *= sign[..., None]
    translation = np.broadcast_to(skeleton.rest_translation, origin.shape).copy()
    translation[:, 0] = origin[:, 0]
    return Animation(times=take.times, rotation=local, translation=translation)
