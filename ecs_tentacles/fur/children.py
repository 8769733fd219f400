"""Child hairs interpolated between the 3 nearest guides on the skin, as groom tools do.

Each child gets a root on the mantle's surface near its parent guide (scattered in the
parent's tangent plane within half the guide's length, then snapped to the surface)
and, once per bind pose, its 3 nearest guides of the same fur with inverse-distance
weights measured between roots on the body. Every frame its curve is its root plus the
weighted sum of those guides' posed offsets from their own roots, scaled by a per-child
length factor, so children follow every rig behaviour and the dynamics in between the
guides. No child point goes below the tangent plane at the child's root; the mantle is
convex, so children stay outside the skin.

`layout` is cached per fur (rebuilt when `FurData.version` or the request changes).
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass, fields
from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.components import Creature
from ecs_tentacles.fur.groom import closest_surface_point
from ecs_tentacles.fur.nearest import nearest
from ecs_tentacles.fur.stores import FurData
from ecs_tentacles.numeric.quaternions import quat_rotate

if TYPE_CHECKING:
    from ecs_tentacles.host import Host

NEIGHBOURS = 3


@dataclass
class ChildLayout:
    """Children of every guide: where they grow and which guides they blend."""

    parent: np.ndarray  # (m,) the guide each child was scattered around
    body: np.ndarray  # (m,) Transform row of the mantle
    root: np.ndarray  # (m, 3) on the skin, mantle frame
    normal: np.ndarray  # (m, 3) the skin's normal there, mantle frame
    neighbours: np.ndarray  # (m, 3) guide rows
    weights: np.ndarray  # (m, 3) summing to 1
    scale: np.ndarray  # (m,) length factor
    jitter: np.ndarray  # (m,) colour factor, per strand


_CACHE: weakref.WeakKeyDictionary[FurData, tuple[tuple[int, ...], ChildLayout]] = (
    weakref.WeakKeyDictionary()
)


def layout(world: Host, per_guide: int | None = None, seed: int = 0) -> ChildLayout:
    """The children of every fur (`per_guide` each, default each fur's `children`)."""
    fur = world.resource(FurData)
    key = (fur.version, len(fur.guides), -1 if per_guide is None else per_guide, seed)
    cached = _CACHE.get(fur)
    if cached is not None and cached[0] == key:
        return cached[1]
    made = _make_layout(world, per_guide, seed)
    _CACHE[fur] = (key, made)
    return made


def subset(made: ChildLayout, keep: np.ndarray) -> ChildLayout:
    """The children of `made` where `keep` (a bool per child) is True, as they were."""
    return ChildLayout(*(getattr(made, f.name)[keep] for f in fields(ChildLayout)))


def parents(fur: FurData, per_guide: int | None) -> np.ndarray:
    """The guide row of every child: `per_guide` each, default each fur's `children`."""
    g = fur.guides
    counts = fur.sets.children[g.fur_row] if per_guide is None else np.full(len(g), per_guide)
    return np.repeat(np.arange(len(g)), counts)


def _make_layout(world: Host, per_guide: int | None, seed: int) -> ChildLayout:
    fur = world.resource(FurData)
    g = fur.guides
    parent = parents(fur, per_guide)
    rng = np.random.default_rng(seed)
    m = len(parent)
    angle = rng.uniform(0.0, 2.0 * np.pi, m)
    reach = 0.5 * g.length[parent] * np.sqrt(rng.random(m))
    side = g.side[parent]
    along = np.cross(g.normal[parent], side)
    scattered = g.root[parent] + reach[:, None] * (
        np.cos(angle)[:, None] * side + np.sin(angle)[:, None] * along
    )
    root = np.empty((m, 3))
    normal = np.empty((m, 3))
    neighbours = np.empty((m, NEIGHBOURS), dtype=np.int64)
    weights = np.empty((m, NEIGHBOURS))
    for f in range(len(fur.sets)):
        mine = np.flatnonzero(g.fur_row[parent] == f)
        if not len(mine):
            continue
        creature = world.component(int(fur.sets.creature[f]), Creature)
        root[mine], normal[mine] = closest_surface_point(
            scattered[mine], creature.mantle_radius, creature.mantle_height
        )
        guides = np.flatnonzero(g.fur_row == f)
        neighbours[mine], weights[mine] = _nearest(root[mine], g.root[guides], guides)
    return ChildLayout(
        parent=parent,
        body=g.body_row[parent],
        root=root,
        normal=normal,
        neighbours=neighbours,
        weights=weights,
        scale=rng.uniform(0.7, 1.0, m),
        jitter=rng.uniform(0.8, 1.15, m),
    )


def _nearest(
    points: np.ndarray, roots: np.ndarray, rows: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The 3 nearest roots of each point (guide rows), nearest first (ties: the lower
    row), and inverse-distance weights; with fewer guides, the last is repeated at
    weight 0."""
    k = min(NEIGHBOURS, len(roots))
    found, d2 = nearest(points, roots, k)
    w = 1.0 / np.maximum(np.sqrt(d2), 1e-6) ** 2
    w /= w.sum(axis=1, keepdims=True)
    pad = NEIGHBOURS - k
    return rows[np.pad(found, ((0, 0), (0, pad)), "edge")], np.pad(w, ((0, 0), (0, pad)))


def point_indices(points: int, keep: int | None) -> np.ndarray:
    """`keep` of a curve's `points` indices, evenly spread, root and tip kept (all: None)."""
    if keep is None or keep >= points:
        return np.arange(points)
    return np.unique(np.round(np.linspace(0, points - 1, max(keep, 2))).astype(np.int64))


def interpolated_children(
    world: Host, children: ChildLayout, keep: int | None = None
) -> np.ndarray:
    """The children's world polylines (m, points, 3) float32, for this frame's guides.

    `keep`: that many points per child (evenly picked along the guides; fewer points
    draw faster, the sandbox's level of detail), else all of them.
    """
    fur = world.resource(FurData)
    picked = point_indices(fur.points, keep)
    if not len(children.parent):
        return np.zeros((0, len(picked), 3), np.float32)
    curves, roots = fur.curves[:, picked], fur.frames[:, 3]
    offsets = np.zeros((len(children.parent), len(picked), 3), np.float32)
    for i in range(NEIGHBOURS):
        rows = children.neighbours[:, i]
        weight = (children.weights[:, i] * children.scale).astype(np.float32)
        offsets += weight[:, None, None] * (curves[rows] - roots[rows][:, None, :])
    quat = world.transforms.quat[children.body]
    root = world.transforms.pos[children.body] + quat_rotate(quat, children.root)
    normal = quat_rotate(quat, children.normal).astype(np.float32)
    height = np.einsum("mpk,mk->mp", offsets, normal)
    offsets -= np.minimum(height, 0.0)[:, :, None] * normal[:, None, :]  # not below the skin
    points: np.ndarray = (root[:, None, :] + offsets).astype(np.float32)
    return points
