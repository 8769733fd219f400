"""Static solids (boxes, cylinders, spheres, convex pieces of meshes): where their tops
are, how far points are from them, and their faces as planes."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class Solid:
    """A static shape: `kind` one of SHAPES; `position` its centre; `rotation` (3, 3) its
    frame; `size` half extents (box), (radius, half height) (cylinder, along its z) or
    (radius,) (sphere); a mesh's convex `pieces`, each a (k, 3) vertex array in its frame."""

    kind: str
    position: np.ndarray
    rotation: np.ndarray
    size: tuple[float, ...] = ()
    pieces: tuple[np.ndarray, ...] = ()
    planes: tuple[np.ndarray, ...] = field(default=(), compare=False)

    @property
    def bound(self) -> float:
        """The radius of a sphere about `position` that holds the whole solid."""
        if self.pieces:
            return float(max(np.linalg.norm(p, axis=1).max() for p in self.pieces))
        return float(np.linalg.norm(self.size)) if self.kind != "sphere" else self.size[0]

    def top(self, xy: np.ndarray) -> np.ndarray:
        """(n,) the height of this solid's top above points `xy` (n, 2), -inf where it is
        not above them (a vertical line through the point misses it). Exact for boxes,
        spheres and convex pieces; cylinders as 48-sided prisms (under 0.3% of the radius)."""
        if self.kind == "sphere":
            d2 = np.sum((xy - self.position[:2]) ** 2, axis=1)
            r2 = self.size[0] ** 2
            return np.where(d2 <= r2, self.position[2] + np.sqrt(np.maximum(r2 - d2, 0.0)), -np.inf)
        out = np.full(len(xy), -np.inf)
        for planes in self._world_planes():
            normal, offset = planes[:, :3], planes[:, 3]
            rest = offset[None, :] - xy @ normal[:, :2].T  # n_z z <= rest, per plane
            up, down = normal[:, 2] > 1e-12, normal[:, 2] < -1e-12
            side = ~(up | down)
            high = np.min(rest[:, up] / normal[up, 2], axis=1) if up.any() else np.inf
            low = np.max(rest[:, down] / normal[down, 2], axis=1) if down.any() else -np.inf
            inside = np.all(rest[:, side] >= -1e-12, axis=1) if side.any() else True
            out = np.maximum(out, np.where(inside & (high >= low), high, -np.inf))
        return out

    def _world_planes(self) -> list[np.ndarray]:
        """Each convex part as world-frame planes (k, 4): outward normal, offset (made once)."""
        cached = self.__dict__.get("_planes_world")
        if cached is None:
            if self.kind == "box":
                local = [_box_planes(np.asarray(self.size))]
            elif self.kind == "cylinder":
                local = [_prism_planes(self.size[0], self.size[1])]
            else:
                local = list(self.planes)
            cached = []
            for p in local:
                normal = p[:, :3] @ self.rotation.T
                cached.append(np.column_stack([normal, p[:, 3] + normal @ self.position]))
            object.__setattr__(self, "_planes_world", cached)  # a cache, not a field
        return cached

    def signed_distance(self, points: np.ndarray) -> np.ndarray:
        """Metres from points (n, 3) to the surface, negative inside."""
        if self.kind == "sphere":  # turning a sphere changes nothing: not turned
            return np.asarray(np.linalg.norm(points - self.position, axis=1) - self.size[0])
        local = (points - self.position) @ self.rotation
        if self.kind == "box":
            return _box_distance(local, np.asarray(self.size))
        if self.kind == "cylinder":
            flat = np.stack([np.hypot(local[:, 0], local[:, 1]), local[:, 2]], axis=1)
            return _box_distance(flat, np.asarray(self.size))
        # convex pieces: the largest plane distance (exact inside, a lower bound outside)
        return np.asarray(
            np.min([np.max(local @ p[:, :3].T - p[:, 3], axis=1) for p in self.planes], axis=0)
        )


def _box_planes(half: np.ndarray) -> np.ndarray:
    normals = np.vstack([np.eye(3), -np.eye(3)])
    return np.column_stack([normals, np.concatenate([half, half])])


def _prism_planes(radius: float, half: float, sides: int = 48) -> np.ndarray:
    """A cylinder along z as a `sides`-gon prism whose faces touch the circle."""
    angle = 2.0 * np.pi * np.arange(sides) / sides
    around = np.column_stack(
        [np.cos(angle), np.sin(angle), np.zeros(sides), np.full(sides, radius)]
    )
    caps = np.array([[0.0, 0.0, 1.0, half], [0.0, 0.0, -1.0, half]])
    return np.vstack([around, caps])


def _box_distance(local: np.ndarray, half: np.ndarray) -> np.ndarray:
    q = np.abs(local) - half
    outside = np.linalg.norm(np.maximum(q, 0.0), axis=1)
    return np.asarray(outside + np.minimum(q.max(axis=1), 0.0))


def convex_planes(vertices: np.ndarray) -> np.ndarray:
    """The faces of the convex hull of `vertices` as planes (k, 4): outward normal, offset."""
    from scipy.spatial import ConvexHull

    hull = ConvexHull(vertices)
    return np.asarray(hull.equations[:, :4] * [1.0, 1.0, 1.0, -1.0])
