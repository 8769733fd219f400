"""Where each creature's root prim is over a chunk of frames, and world points seen from it.

A skinned creature's SkelRoot carries its root motion (`ecs_tentacles.export.skinned_usd`):
the mantle's position, or for a creature replaying a shared clip the ground frame it
walks in (a position on the ground and a heading about +z). Things recorded in world
space that live under the creature's root (suckers, goals, fur guides) are written in
that moving frame, so that USD, and Blender's importer, which ignores
`!resetXformStack!`, both put them back where the take has them.

Reads the arrays it is given; writes nothing.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class RootFrames:
    """Creatures' root frames over a chunk: `origin` (n, C, 3) world metres and `yaw`
    (n, C) radians about +z (None: no turn, a translation only)."""

    origin: np.ndarray
    yaw: np.ndarray | None = None

    def local(self, points: np.ndarray, owners: np.ndarray) -> np.ndarray:
        """World `points` (n, K, 3), item k in the frame of creature `owners[k]` (-1: no
        creature's; left in the world)."""
        owners = np.asarray(owners, dtype=np.int64)
        out = np.array(points, dtype=np.float64)
        own = owners >= 0
        if not own.any():
            return out
        moved = out[:, own] - self.origin[:, owners[own]]
        if self.yaw is not None:
            yaw = self.yaw[:, owners[own]]
            cos, sin = np.cos(yaw), np.sin(yaw)
            x, y = moved[..., 0].copy(), moved[..., 1].copy()
            moved[..., 0] = cos * x + sin * y  # the rotation by -yaw
            moved[..., 1] = -sin * x + cos * y
        out[:, own] = moved
        return out

    def local_pose(
        self, pos: np.ndarray, quat: np.ndarray, owners: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """World poses, positions (n, K, 3) and unit rotations (n, K, 4) w-first, of
        items owned by creatures `owners` (K,), in those creatures' frames."""
        where = self.local(pos, owners)
        turn = np.array(quat, dtype=np.float64)
        if self.yaw is None:
            return where, turn
        half = 0.5 * self.yaw[:, np.asarray(owners, dtype=np.int64)]
        c, s = np.cos(half), np.sin(half)
        w, x, y, z = (turn[..., i].copy() for i in range(4))
        turn[..., 0] = c * w + s * z  # (cos h/2, 0, 0, -sin h/2) * q
        turn[..., 1] = c * x + s * y
        turn[..., 2] = c * y - s * x
        turn[..., 3] = c * z - s * w
        return where, turn
