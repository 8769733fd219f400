"""The static world the creatures stand on: the plane z = 0, or a heightfield, and solids.

Core knows only this description; where it comes from (a scene's `terrain`, noise,
images, mesh files) is the terrain plugin's business (`ecs_tentacles.terrain`), which
provides a `Ground` resource. Without one the world has `FLAT`: the plane z = 0,
exactly as before terrain existed.

    ground = ground_of(world)
    ground.height(xy)            # (n,) surface height under points (n, 2)
    ground.distance(points)      # (n,) metres from points (n, 3) to the nearest surface
    ground.normal(points)        # (n, 3) unit normals of that surface

Reads: nothing of the world. Used by the physics model (`add_to_spec`: every group's
model gets the same static geoms), creature placement (`ecs_tentacles.construction`),
the suckers (they grip any static surface) and the renderer and exporters (`mesh`).
"""

from __future__ import annotations

import hashlib
from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Protocol

import mujoco
import numpy as np

from ecs_tentacles.optional_kernels import OptionalKernels

if TYPE_CHECKING:
    from collections.abc import Sequence

NORMAL_SPAN = 0.05  # metres either side over which the slope under a point is measured
NEAR = 0.5  # metres past a solid's bounding sphere within which distances to it are exact
BEYOND_DROP = 0.002  # metres the plane past a heightfield's edge lies under its lowest point
# the heightfield kernel (numba, when installed; numpy otherwise: the same numbers)
KERNELS = OptionalKernels("ecs_tentacles.physics.kernels", "ECS_TENTACLES_SENSE")


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
        lowest = self.__dict__.get("_lowest")
        if lowest is None:
            lowest = float(self.heights.min())
            object.__setattr__(self, "_lowest", lowest)  # a cache, not a field
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

    def slope_normal(self, xy: np.ndarray) -> np.ndarray:
        """Unit surface normals (n, 3) under `xy` (n, 2), from the heights' gradient."""
        dx, dy = self.cell
        ex, ey = np.array([0.5 * dx, 0.0]), np.array([0.0, 0.5 * dy])
        gx = (self.height(xy + ex) - self.height(xy - ex)) / dx
        gy = (self.height(xy + ey) - self.height(xy - ey)) / dy
        n = np.stack([-gx, -gy, np.ones_like(gx)], axis=1)
        return np.asarray(n / np.linalg.norm(n, axis=1, keepdims=True))


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
        local = (points - self.position) @ self.rotation
        if self.kind == "sphere":
            return np.asarray(np.linalg.norm(local, axis=1) - self.size[0])
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


class StaticSpec(Protocol):
    """What `Ground.add_to_spec` needs of a `mujoco.MjSpec`."""

    worldbody: mujoco.MjsBody

    def add_hfield(self, **kwargs: object) -> mujoco.MjsHField: ...
    def add_mesh(self, **kwargs: object) -> mujoco.MjsMesh: ...


@dataclass(frozen=True)
class Ground:
    """The plane z = 0 (`heightfield` None) or a heightfield, plus static `solids`;
    `friction` overrides the scene's `physics.ground_friction` when given."""

    provided_by = "terrain"

    heightfield: Heightfield | None = None
    solids: tuple[Solid, ...] = ()
    friction: float | None = None

    @property
    def flat(self) -> bool:
        """The plane z = 0 and nothing on it."""
        return self.heightfield is None and not self.solids

    def digest(self) -> str:
        """Identifies this ground's geometry (model sharing, takes)."""
        if self.flat and self.friction is None:
            return "plane"
        h = hashlib.sha256()
        if self.heightfield is not None:
            h.update(np.asarray(self.heightfield.size, np.float64).tobytes())
            h.update(np.ascontiguousarray(self.heightfield.heights, np.float64).tobytes())
        for solid in self.solids:
            h.update(solid.kind.encode())
            for part in (solid.position, solid.rotation, np.asarray(solid.size), *solid.pieces):
                h.update(np.ascontiguousarray(part, np.float64).tobytes())
        h.update(repr(self.friction).encode())
        return h.hexdigest()[:16]

    # -- queries -------------------------------------------------------------------------
    def height(self, xy: np.ndarray) -> np.ndarray:
        """The ground's height (heightfield or plane, not solids) under points `xy` (n, 2)."""
        xy = np.asarray(xy, dtype=np.float64).reshape(-1, 2)
        if self.heightfield is None:
            return np.zeros(len(xy))
        return self.heightfield.height(xy)

    def distance(self, points: np.ndarray) -> np.ndarray:
        """Metres from points (n, 3) to the nearest static surface (negative: inside).

        The heightfield's part is the height above it times the normal's z (exact on a
        plane, close on gentle slopes); solids give their signed distance to points within
        `NEAR` m of their bounding sphere (exact there; farther points may get a larger
        value: every use asks about points at or near a surface).
        """
        points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        if self.heightfield is None:
            best = points[:, 2].copy()
        else:
            xy = points[:, :2]
            normal_z = self.heightfield.slope_normal(xy)[:, 2]
            best = (points[:, 2] - self.heightfield.height(xy)) * normal_z
        if not self.solids:
            return best
        for k, near in self._under_bounds(points, NEAR):
            best[near] = np.minimum(best[near], self.solids[k].signed_distance(points[near]))
        return best

    def _under_bounds(self, points: np.ndarray, pad: float) -> Iterator[tuple[int, np.ndarray]]:
        """(solid, rows of `points`) for each solid whose bounding sphere grown by `pad`
        holds some of `points` (n, 3), or whose bounding circle does for points (n, 2):
        one array test for all solids, then only the solids that hold any point."""
        centres, bounds = self._bounds()
        reach = (bounds + pad) ** 2
        dims = points.shape[1]
        per_chunk = max(1, (1 << 20) // max(len(self.solids), 1))
        for start in range(0, len(points), per_chunk):
            part = points[start : start + per_chunk]
            if dims == 2:
                gaps = part[:, None, :] - centres[None, :, :]
            else:
                gaps = part[:, None, :] - self._positions()[None, :, :]
            inside = np.einsum("nkd,nkd->nk", gaps, gaps) <= reach
            for k in np.flatnonzero(inside.any(axis=0)).tolist():
                yield k, start + np.flatnonzero(inside[:, k])

    def _positions(self) -> np.ndarray:
        """(k, 3) the solids' centres (made once)."""
        cached = self.__dict__.get("_positions_cache")
        if cached is None:
            cached = np.array([s.position for s in self.solids]).reshape(-1, 3)
            object.__setattr__(self, "_positions_cache", cached)  # a cache, not a field
        return cached

    def _bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """(k, 2) solid centres in x, y and (k,) bounding radii (made once)."""
        cached = self.__dict__.get("_bounds_cache")
        if cached is None:
            centres = np.array([s.position[:2] for s in self.solids]).reshape(-1, 2)
            cached = (centres, np.array([s.bound for s in self.solids]))
            object.__setattr__(self, "_bounds_cache", cached)  # a cache, not a field
        return cached

    def solids_near(self, xy: np.ndarray, radius: float) -> np.ndarray:
        """Indices of the solids that may come within `radius` m of point `xy` (x, y):
        their bounding spheres do (a cull before exact tests; a crowd of thousands among
        hundreds of rocks tests each creature against a few)."""
        centres, bounds = self._bounds()
        distance = np.linalg.norm(centres - np.asarray(xy, dtype=np.float64)[:2], axis=1)
        return np.flatnonzero(distance <= bounds + radius)

    def inside_solid(
        self,
        points: np.ndarray,
        radii: np.ndarray | float = 0.0,
        only: np.ndarray | None = None,
    ) -> np.ndarray:
        """(n,) index of the first solid (of `only`, default all) each ball (`points`
        (n, 3), `radii`) reaches into, -1 for none."""
        points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        which = np.full(len(points), -1, dtype=np.int64)
        for k in range(len(self.solids)) if only is None else only.tolist():
            solid = self.solids[k]
            hit = (which < 0) & (solid.signed_distance(points) < radii)
            which[hit] = k
        return which

    def normal(self, points: np.ndarray) -> np.ndarray:
        """Unit normals (n, 3) of the surface nearest each point (`distance`'s gradient)."""
        points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        if self.flat:
            return np.tile([0.0, 0.0, 1.0], (len(points), 1))
        step = 1e-4
        grad = np.empty_like(points)
        for axis in range(3):
            e = np.zeros(3)
            e[axis] = step
            grad[:, axis] = self.distance(points + e) - self.distance(points - e)
        norm = np.linalg.norm(grad, axis=1, keepdims=True)
        up = np.array([0.0, 0.0, 1.0])
        return np.where(norm > 1e-12, grad / np.maximum(norm, 1e-12), up)

    def normal_under(self, xy: np.ndarray) -> np.ndarray:
        """(n, 3) unit normals of the topmost surface under points `xy` (n, 2): the plane
        a creature standing there crawls in."""
        xy = np.asarray(xy, dtype=np.float64).reshape(-1, 2)
        if self.flat:
            return np.tile([0.0, 0.0, 1.0], (len(xy), 1))
        if not self.solids and self.heightfield is not None:
            return self.heightfield.slope_normal(xy)
        # the topmost surface's slope, over NORMAL_SPAN either way
        ex, ey = np.array([NORMAL_SPAN, 0.0]), np.array([0.0, NORMAL_SPAN])
        gx = (self.surface(xy + ex) - self.surface(xy - ex)) / (2 * NORMAL_SPAN)
        gy = (self.surface(xy + ey) - self.surface(xy - ey)) / (2 * NORMAL_SPAN)
        n = np.stack([-gx, -gy, np.ones_like(gx)], axis=1)
        return np.asarray(n / np.linalg.norm(n, axis=1, keepdims=True))

    def ray(self, origin: np.ndarray, direction: np.ndarray) -> np.ndarray | None:
        """Where the ray from `origin` along `direction` first meets the ground or a solid
        (None: it never does; on the plane, only rays going down meet it)."""
        origin = np.asarray(origin, dtype=np.float64).reshape(3)
        direction = np.asarray(direction, dtype=np.float64).reshape(3)
        if self.flat:
            if direction[2] >= 0.0 or origin[2] <= 0.0:
                return None
            return np.asarray(origin + direction * (-origin[2] / direction[2]))
        model, data = self._static()
        hit = np.zeros(1, dtype=np.int32)
        length = float(np.linalg.norm(direction))
        if length == 0.0:
            return None
        unit = direction / length
        distance = mujoco.mj_ray(model, data, origin, unit, None, 1, -1, hit)
        return None if distance < 0 else origin + unit * distance

    def surface(self, xy: np.ndarray) -> np.ndarray:
        """(n,) the height of the topmost surface (ground or solid) under points `xy` (n, 2)."""
        xy = np.asarray(xy, dtype=np.float64).reshape(-1, 2)
        out = self.height(xy)
        if not self.solids:
            return out
        for k, rows in self._under_bounds(xy, 0.0):  # the points under its bounding circle
            out[rows] = np.maximum(out[rows], self.solids[k].top(xy[rows]))
        return out

    def _static(self) -> tuple[mujoco.MjModel, mujoco.MjData]:
        """A model of the ground alone (made once), for ray casts."""
        cached = self.__dict__.get("_static_model")
        if cached is None:
            spec = mujoco.MjSpec()
            self.add_to_spec(spec, 1.0, 1, 1, (0.02, 1.0))
            model = spec.compile()
            data = mujoco.MjData(model)
            mujoco.mj_forward(model, data)
            cached = (model, data)
            object.__setattr__(self, "_static_model", cached)  # a cache, not a field
        return cached

    def lift(self, points: np.ndarray, radii: np.ndarray) -> float:
        """How far to raise balls (`points`, `radii`) laid out on the plane z = 0 so they
        rest on this ground: the largest (ground height - ball bottom)."""
        if self.heightfield is None:
            return 0.0
        bottoms = points[:, 2] - radii
        return float(np.max(self.heightfield.height(points[:, :2]) - bottoms))

    # -- the physics ---------------------------------------------------------------------
    def add_to_spec(
        self,
        spec: StaticSpec,
        friction: float,
        contype: int,
        conaffinity: int,
        solref: Sequence[float],
    ) -> None:
        """Add the ground's static geoms (named `ground...`) to a creature's model spec."""
        common = {
            "friction": [self.friction if self.friction is not None else friction, 0.005, 1e-4],
            "contype": contype,
            "conaffinity": conaffinity,
            "solref": list(solref),
        }
        body = spec.worldbody
        if self.heightfield is None:
            body.add_geom(
                name="ground", type=mujoco.mjtGeom.mjGEOM_PLANE, size=[0, 0, 1.0], **common
            )
        else:
            field_ = self.heightfield
            low, high = float(field_.heights.min()), float(field_.heights.max())
            relief = max(high - low, 1e-6)
            rows, cols = field_.heights.shape
            spec.add_hfield(
                name="ground",
                size=[0.5 * field_.size[0], 0.5 * field_.size[1], relief, 0.5],
                nrow=rows,
                ncol=cols,
                # an array, not a list: a million Python floats took 32 MB per model built
                userdata=((field_.heights - low) / relief).astype(np.float32).ravel(),
            )
            body.add_geom(
                name="ground",
                type=mujoco.mjtGeom.mjGEOM_HFIELD,
                hfieldname="ground",
                pos=[0.0, 0.0, low],
                **common,
            )
            # past the field's edge the world goes on as a plane at its lowest height (a
            # creature that crawls off the edge drops onto it instead of falling forever)
            body.add_geom(
                name="ground/beyond",
                type=mujoco.mjtGeom.mjGEOM_PLANE,
                size=[0, 0, 1.0],
                pos=[0.0, 0.0, low - BEYOND_DROP],
                **common,
            )
        for k, solid in enumerate(self.solids):
            quat = np.zeros(4)
            mujoco.mju_mat2Quat(quat, np.ascontiguousarray(solid.rotation).ravel())
            place = {"pos": solid.position.tolist(), "quat": quat.tolist()}
            if solid.kind == "mesh":
                for p, piece in enumerate(solid.pieces):
                    name = f"ground/solid{k}/piece{p}"
                    spec.add_mesh(name=name, uservert=np.asarray(piece).ravel().tolist())
                    body.add_geom(
                        name=name, type=mujoco.mjtGeom.mjGEOM_MESH, meshname=name, **place, **common
                    )
                continue
            kind = {
                "box": mujoco.mjtGeom.mjGEOM_BOX,
                "cylinder": mujoco.mjtGeom.mjGEOM_CYLINDER,
                "sphere": mujoco.mjtGeom.mjGEOM_SPHERE,
            }[solid.kind]
            size = [*solid.size, 0.0, 0.0][:3]
            body.add_geom(name=f"ground/solid{k}", type=kind, size=size, **place, **common)


FLAT = Ground()


def ground_of(world: object) -> Ground:
    """The world's `Ground` resource (the terrain plugin's), or `FLAT`."""
    getter = getattr(world, "get_resource", None)
    found = getter(Ground) if getter is not None else None
    return found if found is not None else FLAT
