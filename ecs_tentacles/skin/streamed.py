"""Joint rotations of many creatures of one body plan, chunk of frames by chunk.

    rotations = JointRotations(plan.parents, joint_bodies)     # joint_bodies (C, J)
    for first, chunk in source.chunks():
        local = rotations.local(chunk.quat)                   # (n, C, J, 4) w-first

Each creature's joints are its bodies (`Skeleton.bodies`: the mantle, then every link);
a joint turns with its body, so a joint's local rotation is its parent body's world
rotation undone from its own (`ecs_tentacles.skin.skeleton.creature_animation` does
the same for one creature over a whole take). The root's local rotation is the mantle's
world rotation. Signs are made continuous along time across chunks (q and -q are the
same rotation, but interpolating between them takes the long way round): the last
frame of a chunk is kept for the next.

Reads body quaternions; writes nothing. Whole-array work: a chunk of every creature of
a plan at once.
"""

from __future__ import annotations

import numpy as np


def undo(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """conj(a) * b for unit quaternion arrays (..., 4): `b` seen from `a`'s frame (the
    Hamilton product with the conjugate written out: no conjugate array made)."""
    aw, ax, ay, az = np.moveaxis(a, -1, 0)
    bw, bx, by, bz = np.moveaxis(b, -1, 0)
    out = np.empty(np.broadcast_shapes(a.shape, b.shape))
    out[..., 0] = aw * bw + ax * bx + ay * by + az * bz
    out[..., 1] = aw * bx - ax * bw - ay * bz + az * by
    out[..., 2] = aw * by + ax * bz - ay * bw - az * bx
    out[..., 3] = aw * bz - ax * by + ay * bx - az * bw
    return out


class JointRotations:
    """Local joint rotations of creatures sharing a skeleton, continuous over chunks."""

    def __init__(self, parents: np.ndarray, joint_bodies: np.ndarray) -> None:
        self.parents = np.asarray(parents)
        self.bodies = np.asarray(joint_bodies)  # (creatures, joints) take body indices
        self.children = np.flatnonzero(self.parents >= 0)
        self.last: np.ndarray | None = None  # (creatures, joints, 4) the previous frame's

    def world(self, quat: np.ndarray) -> np.ndarray:
        """(n, C, J, 4) unit world rotations of every joint from a chunk's body `quat`."""
        world = quat[:, self.bodies].astype(np.float64)
        world /= np.sqrt(np.einsum("...c,...c->...", world, world))[..., None]
        return world

    def local(self, quat: np.ndarray, yaw: np.ndarray | None = None) -> np.ndarray:
        """(n, C, J, 4) local rotations (the root's: its world rotation, or with `yaw`
        (n, C) that rotation seen from a frame turned by `yaw` radians about +z) for the
        chunk's frames, signs continuous with the chunk before."""
        world = self.world(quat)
        local = world.copy()
        parents = self.parents[self.children]
        local[..., self.children, :] = undo(world[..., parents, :], world[..., self.children, :])
        if yaw is not None:
            self._turned(local, yaw)
        return self.continuous(local)

    def local_at(
        self, quat: np.ndarray, rows: np.ndarray, columns: np.ndarray, yaw: np.ndarray | None
    ) -> np.ndarray:
        """(K, J, 4) local rotations, as `local` makes them, of creature `columns[k]` at
        the chunk's frame `rows[k]` only (pairs in frame order; `yaw` (K,) or None), signs
        continuous with that creature's pair before (this chunk's or an earlier one's)."""
        world = quat[rows[:, None], self.bodies[columns]].astype(np.float64)  # (K, J, 4)
        world /= np.sqrt(np.einsum("...c,...c->...", world, world))[..., None]
        local = world.copy()
        parents = self.parents[self.children]
        local[:, self.children] = undo(world[:, parents], world[:, self.children])
        if yaw is not None:
            self._turned(local, yaw)
        if self.last is None:
            self.last = np.zeros((len(self.bodies), self.bodies.shape[1], 4))
        for row in np.unique(rows).tolist():  # a few frames: whole creatures at once
            pick = np.flatnonzero(rows == row)
            mine = columns[pick]
            flip = np.einsum("kjc,kjc->kj", local[pick], self.last[mine]) < 0
            local[pick] = np.where(flip[..., None], -local[pick], local[pick])
            self.last[mine] = local[pick]
        flipped: np.ndarray = local
        return flipped

    def _turned(self, local: np.ndarray, yaw: np.ndarray) -> None:
        """The roots' rotations in `local` (..., J, 4) seen from frames turned by `yaw`
        (...) radians about +z, in place."""
        half = 0.5 * np.asarray(yaw, dtype=np.float64)[..., None]
        turn = np.zeros((*half.shape, 4))
        turn[..., 0], turn[..., 3] = np.cos(half), np.sin(half)
        roots = self.parents < 0
        local[..., roots, :] = undo(turn, local[..., roots, :])

    def continuous(self, local: np.ndarray) -> np.ndarray:
        """`local` (n, C, J, 4) with each quaternion's sign flipped where that keeps it in
        the previous frame's hemisphere (the previous chunk's last frame too)."""
        flips = np.zeros(local.shape[:-1], dtype=bool)
        flips[1:] = np.einsum("f...c,f...c->f...", local[1:], local[:-1]) < 0
        if self.last is not None:
            flips[0] = np.einsum("...c,...c->...", local[0], self.last) < 0
        sign = np.where(np.cumsum(flips, axis=0) % 2 == 1, -1.0, 1.0)
        local *= sign[..., None]
        self.last = local[-1].copy()
        return local
