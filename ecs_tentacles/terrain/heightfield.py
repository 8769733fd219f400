"""A heightfield: heights on a grid, as MuJoCo's triangles give them under any point.

Its heights come from an optional numba kernel (`terrain.heightfield_kernels`, numpy
otherwise: the same numbers bit for bit).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ecs_tentacles.numeric.optional_kernels import OptionalKernels

BEYOND_DROP = 0.002  # metres the plane past a heightfield's edge lies under its lowest point

# the heightfield kernel (numba, when installed; numpy otherwise: the same numbers)
KERNELS = OptionalKernels("ecs_tentacles.terrain.heightfield_kernels", "ECS_TENTACLES_SENSE")


@dataclass(frozen=True)
class Heightfield:
    """Heights on a grid centred on the origin: `heights` (rows along y from -y/2,
    columns along x from -x/2) in metres over `size` (x, y) metres."""

    size: tuple[float, float]
    heights: np.ndarray

    @property
    def cell(self) -> tuple[float, float]:
        """Metres between samples along x and y."""
        rows, cols = self.heights.shape
        return self.size[0] / (cols - 1), self.size[1] / (rows - 1)

    def height(self, xy: np.ndarray) -> np.ndarray:
        """Heights under points `xy` (n, 2), as MuJoCo's triangles give them; past the
        border, the plane at the lowest height that catches what leaves the field."""
        xy = np.asarray(xy, dtype=np.float64)
        lowest = self._lowest_height()
        fast = KERNELS.get()
        if fast is not None:  # the same numbers, in one pass instead of twenty
            out = np.empty(len(xy))
            fast.field_heights(self.heights, self.size[0], self.size[1], lowest, xy, out)
            return out
        rows, cols = self.heights.shape
        outside = (np.abs(xy[:, 0]) > 0.5 * self.size[0]) | (np.abs(xy[:, 1]) > 0.5 * self.size[1])
        u = np.clip((xy[:, 0] / self.size[0] + 0.5) * (cols - 1), 0.0, cols - 1.0)
        v = np.clip((xy[:, 1] / self.size[1] + 0.5) * (rows - 1), 0.0, rows - 1.0)
        i = np.minimum(v.astype(np.int64), rows - 2)
        j = np.minimum(u.astype(np.int64), cols - 2)
        fu, fv = u - j, v - i
        h = self.heights
        h00, h01, h10, h11 = h[i, j], h[i, j + 1], h[i + 1, j], h[i + 1, j + 1]
        # each cell is two triangles split along (i, j) - (i + 1, j + 1)
        lower = fu >= fv  # below the diagonal: (i, j), (i, j + 1), (i + 1, j + 1)
        below = h00 + fu * (h01 - h00) + fv * (h11 - h01)
        above = h00 + fv * (h10 - h00) + fu * (h11 - h10)
        return np.where(outside, lowest, np.where(lower, below, above))

    def _lowest_height(self) -> float:
        """The lowest height of the field (made once)."""
        lowest = self.__dict__.get("_lowest")
        if lowest is None:
            lowest = float(self.heights.min())
            object.__setattr__(self, "_lowest", lowest)  # a cache, not a field
        return float(lowest)

    def slope_normal(self, xy: np.ndarray) -> np.ndarray:
        """Unit surface normals (n, 3) under `xy` (n, 2), from the heights' gradient."""
        fast = KERNELS.get()
        if fast is not None:  # the same numbers, in one pass instead of fifteen
            # C order always: the kernel compiled for one layout, not a strided one too
            xy = np.ascontiguousarray(np.asarray(xy, dtype=np.float64).reshape(-1, 2))
            out = np.empty((len(xy), 3))
            cell = np.array(self.cell, dtype=np.float64)
            fast.field_normals(self.heights, self.size[0], self.size[1], self._lowest_height(),
                               cell, xy, out)  # fmt: skip
            return out
        dx, dy = self.cell
        ex, ey = np.array([0.5 * dx, 0.0]), np.array([0.0, 0.5 * dy])
        gx = (self.height(xy + ex) - self.height(xy - ex)) / dx
        gy = (self.height(xy + ey) - self.height(xy - ey)) / dy
        n = np.stack([-gx, -gy, np.ones_like(gx)], axis=1)
        return np.asarray(n / np.linalg.norm(n, axis=1, keepdims=True))
