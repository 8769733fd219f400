"""Contact between physics groups: proxies of nearby creatures' bodies.

Each creature's model holds a pool of kinematic (mocap) capsules and cylinders
(`ecs_tentacles.physics.model`). Before each frame's step, every creature near
another gets proxies, sized and posed like the other creature's bodies as they were
at the end of the last frame; MuJoCo then pushes the creature out of them. Both
creatures see each other this way, so they push each other apart, wherever their
groups are. Far from everyone, a creature's proxies stay parked out of reach.

All the per-frame work is array math over the bodies of creatures that are near
someone: bounding spheres per creature, candidate bodies inside a neighbour's sphere,
and the nearest ones kept when more are near than the pool holds.
"""

from __future__ import annotations

import itertools
from typing import TYPE_CHECKING

import mujoco
import numpy as np

from ecs_tentacles.physics.model import PROXY_CAPSULES, PROXY_CYLINDERS

if TYPE_CHECKING:
    from ecs_tentacles.physics.group import PhysicsGroup
    from ecs_tentacles.store import TransformStore

MARGIN = 0.05  # metres: a body this close to a neighbour's sphere gets a proxy
POOL = np.array([PROXY_CAPSULES, PROXY_CYLINDERS])
CAPSULE, CYLINDER = 0, 1


class ContactProxies:
    """Places every group's proxies from the Transform store, once per frame."""

    def __init__(self, groups: list[PhysicsGroup]):
        self.groups = groups
        rows, owner, kind, size = [], [], [], []
        for group in groups:
            m = group.model
            geoms = m.body_geomadr[group.body_ids]
            rows.append(group.body_rows)
            owner.append(np.full(len(geoms), group.index))
            cylinder = m.geom_type[geoms] == mujoco.mjtGeom.mjGEOM_CYLINDER
            kind.append(np.where(cylinder, CYLINDER, CAPSULE))
            size.append(m.geom_size[geoms, :2])
        empty = np.zeros(0, dtype=np.int64)
        self.rows = np.concatenate(rows) if rows else empty
        self.owner = np.concatenate(owner) if owner else empty
        self.kind = np.concatenate(kind) if kind else empty
        self.size = np.concatenate(size) if size else np.zeros((0, 2))
        radius, half = self.size[:, 0], self.size[:, 1]
        self.rbound = np.where(self.kind == CYLINDER, np.hypot(radius, half), radius + half)
        self.aabb = np.zeros((len(self.rows), 6))
        self.aabb[:, 3:5] = radius[:, None]
        self.aabb[:, 5] = np.where(self.kind == CYLINDER, half, half + radius)
        counts = np.bincount(self.owner, minlength=len(groups)) if len(groups) else empty
        self.start = np.concatenate([[0], np.cumsum(counts)[:-1]]).astype(np.int64)
        self.count = counts.astype(np.int64)
        self.mantle = self.start  # a group's first body is its mantle

    def update(self, transforms: TransformStore) -> None:
        """Give every creature proxies of the other creatures' bodies near it."""
        if len(self.groups) < 2:
            return
        self._place(transforms.pos[self.rows], transforms.quat[self.rows])

    @property
    def in_use(self) -> bool:
        """Some creature is near another (its proxies are placed)."""
        return any(group.proxies_used for group in self.groups)

    def refresh(self, transforms: TransformStore) -> None:
        """Move the proxies to where the bodies are now, within the frame.

        Bodies of creatures near someone are read from their MuJoCo data (as of their
        last substep); every other body is as the frame started."""
        pos, quat = transforms.pos[self.rows], transforms.quat[self.rows]
        for group in self.groups:
            if group.proxies_used:
                rows = slice(
                    self.start[group.index], self.start[group.index] + self.count[group.index]
                )
                pos[rows] = group.data.xpos[group.body_ids]
                quat[rows] = group.data.xquat[group.body_ids]
        self._place(pos, quat)

    def _place(self, pos: np.ndarray, quat: np.ndarray) -> None:
        centre = pos[self.mantle]
        reach = np.linalg.norm(pos - centre[self.owner], axis=1) + self.rbound
        radius = np.maximum.reduceat(reach, self.start)
        a, b = _near_pairs(centre, radius)
        placed = self._assign(a, b, pos, centre, radius) if len(a) else {}
        for group in self.groups:
            found = placed.get(group.index)
            if group.proxies_used:
                _park(group)
            if found is None:
                continue
            body, slot = found
            m, d = group.model, group.data
            geoms, mocap = group.proxy_geoms[slot], group.proxy_mocap[slot]
            d.mocap_pos[mocap] = pos[body]
            d.mocap_quat[mocap] = quat[body]
            m.geom_size[geoms, :2] = self.size[body]
            m.geom_rbound[geoms] = self.rbound[body]
            m.geom_aabb[geoms] = self.aabb[body]
            group.proxies_used = len(slot)

    def _assign(
        self, a: np.ndarray, b: np.ndarray, pos: np.ndarray, centre: np.ndarray, radius: np.ndarray
    ) -> dict[int, tuple[np.ndarray, np.ndarray]]:
        """Group index -> (source bodies, proxy slots): b's bodies inside a's sphere, nearest
        first, as many as the pool of each kind holds."""
        per = self.count[b]
        pair = np.repeat(np.arange(len(a)), per)
        body = np.arange(per.sum()) - np.repeat(np.cumsum(per) - per, per) + self.start[b][pair]
        who = a[pair]
        gap = np.linalg.norm(pos[body] - centre[who], axis=1) - self.rbound[body] - radius[who]
        keep = gap < MARGIN
        who, body, gap = who[keep], body[keep], gap[keep]
        if not len(who):
            return {}
        crowded = np.bincount(who, minlength=len(self.groups)) > POOL.min()
        if crowded[who].any():  # more candidates than proxies: rank by the nearest own body
            some = np.flatnonzero(crowded[who])
            gap[some] = self._body_gaps(who[some], body[some], pos)
        order = np.lexsort((gap, self.kind[body], who))
        who, body = who[order], body[order]
        group_kind = who * 2 + self.kind[body]
        slot = np.arange(len(body)) - np.searchsorted(group_kind, group_kind, side="left")
        fits = slot < POOL[self.kind[body]]
        who, body, slot = who[fits], body[fits], slot[fits]
        slot = slot + np.where(self.kind[body] == CYLINDER, PROXY_CAPSULES, 0)
        bounds = np.flatnonzero(np.r_[True, who[1:] != who[:-1], True])
        return {int(who[s]): (body[s:e], slot[s:e]) for s, e in itertools.pairwise(bounds)}

    def _body_gaps(self, who: np.ndarray, body: np.ndarray, pos: np.ndarray) -> np.ndarray:
        """Gap between each candidate body and the nearest body of creature `who`."""
        per = self.count[who]
        pair = np.repeat(np.arange(len(who)), per)
        own = np.arange(per.sum()) - np.repeat(np.cumsum(per) - per, per) + self.start[who][pair]
        gap = np.linalg.norm(pos[own] - pos[body[pair]], axis=1) - self.rbound[own]
        nearest = np.minimum.reduceat(gap, np.cumsum(per) - per)
        return nearest - self.rbound[body]


def _park(group: PhysicsGroup) -> None:
    group.data.mocap_pos[group.proxy_mocap] = group.proxy_park
    group.proxies_used = 0


def _near_pairs(centre: np.ndarray, radius: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Ordered pairs (a, b), a != b, whose spheres come within MARGIN of each other."""
    n = len(centre)
    found_a, found_b = [], []
    block = max(1, 4_000_000 // max(n, 1))  # bound the (block, n) distance matrix
    for lo in range(0, n, block):
        hi = min(n, lo + block)
        gap = np.linalg.norm(centre[lo:hi, None, :] - centre[None, :, :], axis=2)
        gap -= radius[lo:hi, None] + radius[None, :]
        near = gap < MARGIN
        near[np.arange(hi - lo), np.arange(lo, hi)] = False
        ia, ib = np.nonzero(near)
        found_a.append(ia + lo)
        found_b.append(ib)
    return np.concatenate(found_a), np.concatenate(found_b)
