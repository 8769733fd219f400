"""`TerrainGround`: the ground a scene's `terrain` makes: a heightfield (or the plane
z = 0) and static solids, with every query the core `Ground` protocol asks for.

    ground = TerrainGround(Heightfield(heights, (14, 10)), (Solid("sphere", ...),))
    ground.height(xy)            # (n,) surface height under points (n, 2)
    ground.distance(points)      # (n,) metres from points (n, 3) to the nearest surface
    ground.normal(points)        # (n, 3) unit normals of that surface

The terrain plugin provides it as the world's resource (`ground_of(world)` finds it);
the physics model gets its geoms (`add_to_spec`, through the `StaticGeometry`
registry), the renderer and takes its meshes (`meshes`, `ground_meshes.py`).
"""

from __future__ import annotations

import hashlib
from collections.abc import Iterator
from dataclasses import dataclass

import mujoco
import numpy as np

from ecs_tentacles.ground import GroundMesh, Plane, StaticContact, StaticSpec, ground_of
from ecs_tentacles.numeric.optional_kernels import OptionalKernels
from ecs_tentacles.terrain.convex_pieces import ConvexPieces
from ecs_tentacles.terrain.ground_meshes import ground_meshes
from ecs_tentacles.terrain.heightfield import BEYOND_DROP, Heightfield
from ecs_tentacles.terrain.shapes import Solid

NORMAL_SPAN = 0.05  # metres either side over which the slope under a point is measured
NEAR = 0.5  # metres past a solid's bounding sphere within which distances to it are exact
# the spheres' queries by numba when installed (`terrain.solid_kernels`); =numpy: numpy
KERNELS = OptionalKernels("ecs_tentacles.terrain.solid_kernels", "ECS_TENTACLES_SOLIDS")


@dataclass(frozen=True)
class TerrainGround:
    """The plane z = 0 (`heightfield` None) or a heightfield, plus static `solids`;
    `friction` overrides the scene's `physics.ground_friction` when given. A core
    `ecs_tentacles.ground.Ground` (every query it asks for, and the meshes)."""

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
        for k, near in self._under_bounds(points, NEAR, self._one_by_one()):
            best[near] = np.minimum(best[near], self.solids[k].signed_distance(points[near]))
        fast = KERNELS.get()
        self._pieces().lower_distances(points, NEAR, best, fast)  # the meshes', in one pass
        if fast is not None and self._spheres()[0].size:  # the spheres, in one pass
            fast.sphere_distances(points, *self._spheres()[1:], NEAR, best)
        return best

    def _under_bounds(
        self, points: np.ndarray, pad: float | np.ndarray, among: np.ndarray | None = None
    ) -> Iterator[tuple[int, np.ndarray]]:
        """(solid, rows of `points`) for each solid (of `among`, default all) whose
        bounding sphere grown by `pad` (one for all points, or one per point) holds some
        of `points` (n, 3), or whose bounding circle does for points (n, 2): one array
        test for all solids, then only the solids that hold any point. The squares are
        summed (x^2 + y^2) + z^2, as the sphere kernels sum them."""
        centres, bounds = self._bounds()
        solids = np.arange(len(self.solids)) if among is None else among
        if not len(solids):
            return
        pads = np.broadcast_to(np.asarray(pad, dtype=np.float64), (len(points),))
        dims = points.shape[1]
        per_chunk = max(1, (1 << 20) // len(solids))
        middles = centres[solids] if dims == 2 else self._positions()[solids]
        reaches = bounds[solids]
        fast = KERNELS.get()
        for start in range(0, len(points), per_chunk):
            part = points[start : start + per_chunk]
            if fast is not None:  # the same test, without the (points, solids, 2) gaps
                inside = fast.under_bounds(
                    np.ascontiguousarray(part, dtype=np.float64),
                    np.ascontiguousarray(middles, dtype=np.float64),
                    np.ascontiguousarray(reaches, dtype=np.float64),
                    np.ascontiguousarray(pads[start : start + per_chunk], dtype=np.float64),
                )
            else:
                gaps = part[:, None, :] - middles[None, :, :]
                squares = gaps[:, :, 0] ** 2 + gaps[:, :, 1] ** 2
                if dims == 3:
                    squares += gaps[:, :, 2] ** 2
                reach = (reaches[None, :] + pads[start : start + per_chunk, None]) ** 2
                inside = squares <= reach
            for k in np.flatnonzero(inside.any(axis=0)).tolist():
                yield int(solids[k]), start + np.flatnonzero(inside[:, k])

    def _spheres(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The spheres among the solids: (k,) their indices, (k, 3) centres and (k,)
        radii (made once)."""
        cached = self.__dict__.get("_spheres_cache")
        if cached is None:
            ids = [k for k, s in enumerate(self.solids) if s.kind == "sphere"]
            centres = np.array([self.solids[k].position for k in ids], dtype=np.float64)
            radii = np.array([self.solids[k].size[0] for k in ids], dtype=np.float64)
            cached = (np.array(ids, dtype=np.int64), centres.reshape(-1, 3), radii)
            object.__setattr__(self, "_spheres_cache", cached)  # a cache, not a field
        return cached

    def _by_numpy(self) -> np.ndarray | None:
        """The solids numpy answers for, solid by solid: all of them (None), or, when the
        sphere kernels will answer for the spheres, the others."""
        if KERNELS.get() is None or not self._spheres()[0].size:
            return None
        others = self.__dict__.get("_others_cache")
        if others is None:
            others = np.setdiff1d(np.arange(len(self.solids)), self._spheres()[0])
            object.__setattr__(self, "_others_cache", others)  # a cache, not a field
        return others

    def _one_by_one(self) -> np.ndarray:
        """The solids `distance` and `touches_obstacle` ask numpy about solid by solid:
        `_by_numpy`'s less the meshes (`_pieces` answers for those in one pass)."""
        cached = self.__dict__.get("_one_by_one_cache")
        if cached is None:
            among = self._by_numpy()
            among = np.arange(len(self.solids)) if among is None else among
            cached = np.array([k for k in among.tolist() if self.solids[k].kind != "mesh"])
            cached = cached.astype(np.int64)
            object.__setattr__(self, "_one_by_one_cache", cached)  # a cache, not a field
        return cached

    def _pieces(self) -> ConvexPieces:
        """The mesh solids' convex pieces as arrays (made once)."""
        cached = self.__dict__.get("_pieces_cache")
        if cached is None:
            cached = ConvexPieces.of(self.solids)
            object.__setattr__(self, "_pieces_cache", cached)  # a cache, not a field
        return cached

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
        # the four sides' heights in one call (each point's height is its own)
        count = len(xy)
        sides = self.surface(np.vstack([xy + ex, xy - ex, xy + ey, xy - ey]))
        east, west = sides[:count], sides[count : 2 * count]
        north, south = sides[2 * count : 3 * count], sides[3 * count :]
        n = np.empty((count, 3))
        n[:, 0] = -((east - west) / (2 * NORMAL_SPAN))
        n[:, 1] = -((north - south) / (2 * NORMAL_SPAN))
        n[:, 2] = 1.0
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
        # the points under each solid's bounding circle
        for k, rows in self._under_bounds(xy, 0.0, self._by_numpy()):
            out[rows] = np.maximum(out[rows], self.solids[k].top(xy[rows]))
        fast = KERNELS.get()
        if fast is not None and self._spheres()[0].size:  # the spheres, in one pass
            fast.sphere_tops(xy, *self._spheres()[1:], out)
        return out

    def _static(self) -> tuple[mujoco.MjModel, mujoco.MjData]:
        """A model of the ground alone (made once), for ray casts."""
        cached = self.__dict__.get("_static_model")
        if cached is None:
            spec = mujoco.MjSpec()
            self.add_to_spec(spec, StaticContact(1.0, 1, 1, (0.02, 1.0)))
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

    # -- what the core protocol asks beyond the queries ---------------------------------
    @property
    def extent(self) -> np.ndarray | None:
        """(2,) half sizes of the heightfield in x, y; None without one."""
        if self.heightfield is None:
            return None
        return 0.5 * np.asarray(self.heightfield.size, dtype=np.float64)

    @property
    def has_obstacles(self) -> bool:
        return bool(self.solids)

    def touches_obstacle(self, centres: np.ndarray, reach: np.ndarray) -> np.ndarray:
        """(n,) whose sphere (`centres` (n, 3), `reach` (n,)) meets an obstacle: bounding
        spheres cull, then each obstacle's signed distance decides."""
        centres = np.asarray(centres, dtype=np.float64).reshape(-1, 3)
        # one a ball, as the kernel reads them (a single reach is one for every ball)
        reach = np.ascontiguousarray(
            np.broadcast_to(np.asarray(reach, dtype=np.float64), (len(centres),))
        )
        near = np.zeros(len(centres), dtype=bool)
        fast = KERNELS.get()
        if fast is not None and self._spheres()[0].size:  # the spheres, in one pass
            fast.sphere_touches(centres, reach, *self._spheres()[1:], near)
        # each ball its own pad
        for k, rows in self._under_bounds(centres, reach, self._one_by_one()):
            rows = rows[~near[rows]]
            if len(rows):
                near[rows] = self.solids[k].signed_distance(centres[rows]) <= reach[rows]
        self._pieces().touch(centres, reach, near, fast)  # the meshes', in one pass
        return near

    def obstacle_spans(self) -> tuple[np.ndarray, np.ndarray]:
        """(k, 2) the obstacles' centres in x, y and (k,) their largest half extents."""
        centres = np.array([s.position[:2] for s in self.solids]).reshape(-1, 2)
        spans = [
            max(s.size) if s.size else max(np.abs(p).max() for p in s.pieces) for s in self.solids
        ]
        return centres, np.array(spans, dtype=np.float64)

    def meshes(self) -> list[GroundMesh]:
        """The heightfield's surface, the ground beyond its edge and the obstacles."""
        return ground_meshes(self.heightfield, self.solids)

    # -- the physics ---------------------------------------------------------------------
    def add_to_spec(self, spec: StaticSpec, contact: StaticContact) -> None:
        """Add the ground's static geoms (named `ground...`) to a creature's model spec."""
        common = contact.geom(self.friction)
        body = spec.worldbody
        if self.heightfield is None:  # the plane, as the world without a terrain has it
            Plane(self.friction).add_to_spec(spec, contact)
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


def terrain_ground(world: object) -> TerrainGround:
    """The world's ground as the terrain plugin made it (an empty one on the plane)."""
    ground = ground_of(world)
    return ground if isinstance(ground, TerrainGround) else TerrainGround(friction=ground.friction)
