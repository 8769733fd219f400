"""Every convex piece of the mesh obstacles (rocks, meshes' pieces) in one set of arrays,
so `TerrainGround.distance` and `touches_obstacle` ask about all of them in one numpy
pass instead of a loop over solids (a rocky crowd of 64 has some 40 rocks; each query
holds a few hundred points, a few dozen near a rock: the loop's per-solid calls were
most of its cost).

    pieces = ConvexPieces.of(solids)
    pieces.lower_distances(points, pad, best)   # best (n,) lowered to each piece's distance
    pieces.touch(points, reach, near)           # near (n,) set where a ball meets a piece

A piece's signed distance is its largest plane distance, as `Solid.signed_distance`
takes it (exact inside, a lower bound outside); its faces are world-frame planes padded
to one count (a pad's plane is never the largest). Reads the solids; writes only the
arrays it is handed.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from types import ModuleType

import numpy as np

from ecs_tentacles.terrain.shapes import Solid


@dataclass(frozen=True)
class ConvexPieces:
    """`centres` (m, 3) and `bounds` (m,): a sphere round each piece; `normals` (m, f, 3)
    and `offsets` (m, f): its faces (`normal . x <= offset` inside), padded."""

    centres: np.ndarray
    bounds: np.ndarray
    normals: np.ndarray
    offsets: np.ndarray

    @classmethod
    def of(cls, solids: Sequence[Solid]) -> ConvexPieces:
        """The pieces of every mesh solid among `solids` (none: empty arrays)."""
        faces, centres, bounds = [], [], []
        for solid in solids:
            if solid.kind != "mesh":
                continue
            for planes in solid._world_planes():
                faces.append(planes)
                centres.append(solid.position)
                bounds.append(solid.bound)
        most = max((len(f) for f in faces), default=0)
        normals = np.zeros((len(faces), most, 3))
        offsets = np.full((len(faces), most), np.inf)  # a pad: -inf from every point
        for i, planes in enumerate(faces):
            normals[i, : len(planes)] = planes[:, :3]
            offsets[i, : len(planes)] = planes[:, 3]
        return cls(np.array(centres).reshape(-1, 3), np.array(bounds), normals, offsets)

    def __len__(self) -> int:
        return len(self.bounds)

    def _arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The pieces' arrays as the kernels read them."""
        return self.centres, self.bounds, self.normals, self.offsets

    def _pairs(self, points: np.ndarray, pad: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(point rows, piece indices) of each point within its `pad` of a piece's sphere:
        squares summed (x^2 + y^2) + z^2, as the kernels sum them."""
        gaps = points[:, None, :] - self.centres[None, :, :]
        reach = self.bounds[None, :] + pad[:, None]
        squares = (gaps[..., 0] * gaps[..., 0] + gaps[..., 1] * gaps[..., 1]) + gaps[..., 2] * gaps[
            ..., 2
        ]
        rows, pieces = np.nonzero(squares <= reach * reach)
        return rows, pieces

    def _distances(self, points: np.ndarray, pieces: np.ndarray) -> np.ndarray:
        """Each point's signed distance from its piece (one piece a point): dot products
        summed x, y, z in that order (`terrain.solid_kernels` sums them so; numpy's
        einsum sums in an order of its own, which may differ between CPUs)."""
        normals = self.normals[pieces]
        planes = (
            points[:, None, 0] * normals[..., 0] + points[:, None, 1] * normals[..., 1]
        ) + points[:, None, 2] * normals[..., 2]
        planes -= self.offsets[pieces]
        return np.asarray(planes.max(axis=1))

    def lower_distances(
        self, points: np.ndarray, pad: float, best: np.ndarray, fast: ModuleType | None = None
    ) -> None:
        """`best` (n,) lowered to each piece's signed distance from points (n, 3) within
        `pad` of its sphere (farther ones are left as they are); by `fast`'s kernel when
        given (`terrain.solid_kernels`: the same numbers, no (points, pieces) arrays)."""
        if not len(self) or not len(points):
            return
        if fast is not None:
            fast.piece_distances(points, pad, *self._arrays(), best)
            return
        rows, pieces = self._pairs(points, np.full(len(points), pad))
        if len(rows):
            np.minimum.at(best, rows, self._distances(points[rows], pieces))

    def touch(
        self,
        points: np.ndarray,
        reach: np.ndarray,
        near: np.ndarray,
        fast: ModuleType | None = None,
    ) -> None:
        """`near` (n,) set where the ball at `points` (n, 3) of radius `reach` (n,) meets a
        piece (its signed distance from the point at most `reach`); by `fast`'s kernel
        when given."""
        if not len(self) or not len(points):
            return
        if fast is not None:
            fast.piece_touches(points, reach, *self._arrays(), near)
            return
        rows, pieces = self._pairs(points, reach)
        if len(rows):
            hit = self._distances(points[rows], pieces) <= reach[rows]
            near[rows[hit]] = True
