"""Paths around obstacles: a cost grid of the ground, minimum-cost routes across it, and
the `Navigator` that steers each creature along its route.

    grid = CostGrid.of(ground, reach=1.0, around=points)   # None: nothing to steer around
    waypoints = grid.route(start_xy, goal_xy)               # (k, 2), ending at the goal
    survey = Survey.of(ground, points); survey.grid(1.0)     # the same, the ground once
    world.resource(Navigator).waypoints(row)                # a creature's planned path

The grid covers the ground's extent (the heightfield, or the obstacles and `around`
points with a margin) in `CELL` m cells, each at the height of the topmost surface
there (obstacle tops included: a ramp or a platform is ground to crawl on). A wall is
where that surface rises more than `STEP` from one cell to the next; cells within
`BODY` of a wall's foot are impassable and the cost rises toward walls within the
creature's `reach` (the footprints inflated by the reach, so tentacles fit past
unless there is no other way), and with the slope (`SLOPE_COST` per unit of
tan(slope); steeper than `MAX_SLOPE` is impassable). Routes are scikit-image's minimum-cost paths
(`MCP_Geometric`, 8-connected), pulled tight: a waypoint is kept only where the
straight line to the next one would cross an impassable cell (with numba, one kernel
does both and finds the same cells: `route_kernels`). The ground's part (its
walls, the room beside them, its slopes: `Survey`) is made once; each creature plans on
the grid of its own reach, so its route does not depend on which other creatures share
its world (a shard of a bake plans as the whole crowd does); the last `KEPT_GRIDS`
grids are kept (a grid from the survey is a few array operations, a route far more).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, TypeAlias

import numpy as np

from ecs_tentacles.ground import Ground, ground_of
from ecs_tentacles.locomotion.stores import CreatureGaitStore, LocomotionStores
from ecs_tentacles.numeric.optional_kernels import OptionalKernels

if TYPE_CHECKING:
    from ecs_tentacles.host import Host
    from ecs_tentacles.roster_change import RosterChange

CELL = 0.1  # metres a side
MARGIN = 2.0  # metres of grid around obstacles and the creatures' points
SLOPE_COST = 4.0  # extra cost per unit of tan(slope)
STEP = 0.12  # metres: a rise steeper than this from one cell to the next is a wall
MAX_SLOPE = 1.0  # tan(45 degrees): steeper ground is not crawled up
BODY = 0.45  # metres from a wall's foot a creature's mantle keeps (impassable closer)
NEAR_COST = 6.0  # extra cost at a wall's foot, falling to 0 at a creature's reach
MAX_CELLS = 1_000_000  # 100 m x 100 m at 10 cm; larger extents get coarser cells
WAYPOINT_RADIUS = 0.35  # metres: a waypoint this close is passed
STUCK_SECONDS = 8.0  # no progress toward a waypoint this long: plan again
PROGRESS = 0.1  # metres closer that count as progress
KEPT_GRIDS = 16  # cost grids kept, one a reach (a crowd of one body plan needs one)

# a route's search and pulling tight by numba when installed (`locomotion.route_kernels`,
# the same cells); ECS_TENTACLES_ROUTES=numpy: scikit-image's search and Python's loops
KERNELS = OptionalKernels("ecs_tentacles.locomotion.route_kernels", "ECS_TENTACLES_ROUTES")

# what a snapshot keeps: routes by creature row, and the planned, best and since columns
NavigationState: TypeAlias = tuple[dict[int, np.ndarray], np.ndarray, np.ndarray, np.ndarray]


@dataclass
class Survey:
    """What every creature's cost grid shares: `room` (metres from each cell to the
    nearest wall's foot) and `slope` (tan of the slope, 0 on walls) of `cell` m cells
    from `origin` (x, y), rows along y."""

    origin: np.ndarray
    cell: float
    room: np.ndarray
    slope: np.ndarray

    @classmethod
    def of(cls, ground: Ground, around: np.ndarray) -> Survey | None:
        """The ground's survey over its extent (or the obstacles' and the `around`
        points' with a margin); None when the ground has no obstacles."""
        if not ground.has_obstacles:
            return None
        from scipy.ndimage import distance_transform_edt

        low, high = _extent(ground, np.asarray(around, dtype=np.float64).reshape(-1, 2))
        cell = max(CELL, float(np.sqrt(np.prod(high - low) / MAX_CELLS)))
        columns, rows = (np.ceil((high - low) / cell).astype(int) + 1).tolist()
        x = low[0] + cell * np.arange(columns)
        y = low[1] + cell * np.arange(rows)
        gx, gy = np.meshgrid(x, y)
        top = ground.surface(np.column_stack([gx.ravel(), gy.ravel()])).reshape(rows, columns)
        # a wall is where the topmost surface rises more than STEP from one cell to the next
        padded = np.pad(top, 1, mode="edge")
        rise = np.zeros_like(top)
        for dr, dc in ((0, 1), (2, 1), (1, 0), (1, 2)):
            neighbour = padded[dr : dr + rows, dc : dc + columns]
            rise = np.maximum(rise, neighbour - top)
        wall = rise > STEP
        room = distance_transform_edt(~wall) * cell  # metres to the nearest wall's foot
        gy_, gx_ = np.gradient(top, cell)
        slope = np.hypot(gx_, gy_)
        slope[wall] = 0.0
        return cls(low, cell, room, slope)

    def grid(self, reach: float, body: float = BODY) -> CostGrid:
        """The grid for creatures of `reach` m whose bodies need `body` m of room."""
        room, slope = self.room, self.slope
        costs = 1.0 + SLOPE_COST * slope
        costs += NEAR_COST * np.clip((reach - room) / max(reach, 1e-9), 0.0, 1.0)
        costs[(room < body) | (slope > MAX_SLOPE)] = np.inf
        return CostGrid(self.origin, self.cell, costs)


@dataclass
class CostGrid:
    """Costs (rows along y, columns along x) of `cell` m cells from `origin` (x, y)."""

    origin: np.ndarray
    cell: float
    costs: np.ndarray  # inf where impassable

    @classmethod
    def of(
        cls, ground: Ground, reach: float, around: np.ndarray, body: float = BODY
    ) -> CostGrid | None:
        """The grid for creatures of `reach` m whose bodies need `body` m of room; None
        when the ground has no obstacles."""
        survey = Survey.of(ground, around)
        return None if survey is None else survey.grid(reach, body)

    def index(self, xy: np.ndarray) -> tuple[int, int]:
        """(row, column) of the cell holding point `xy`, clipped to the grid."""
        col, row = np.round((np.asarray(xy, dtype=np.float64) - self.origin) / self.cell)
        rows, columns = self.costs.shape
        return int(np.clip(row, 0, rows - 1)), int(np.clip(col, 0, columns - 1))

    def point(self, index: tuple[int, int]) -> np.ndarray:
        return self.origin + self.cell * np.array([index[1], index[0]], dtype=np.float64)

    def route(self, start: np.ndarray, goal: np.ndarray) -> np.ndarray | None:
        """Waypoints (k, 2) from near `start` to `goal` (the last one), or None when no
        passable route joins them. A start or goal inside an inflated footprint moves
        to the nearest passable cell first."""
        begin = self._passable_near(self.index(start))
        end = self._passable_near(self.index(goal))
        if begin is None or end is None:
            return None
        fast = KERNELS.get()
        if fast is None:
            kept = self._kept_cells(begin, end)
        else:
            cells = fast.route_cells(self.costs, np.array(begin), np.array(end))
            kept = [(int(r), int(c)) for r, c in cells] if len(cells) else None
        if kept is None:
            return None
        points = [self.point(c) for c in kept[1:-1]]
        return np.array([*points, np.asarray(goal, dtype=np.float64)[:2]]).reshape(-1, 2)

    def _kept_cells(
        self, begin: tuple[int, int], end: tuple[int, int]
    ) -> list[tuple[int, int]] | None:
        """The cells of the minimum-cost path from `begin` to `end` pulled tight, by
        scikit-image and Python (`route_kernels.route_cells` without numba)."""
        from skimage.graph import MCP_Geometric

        mcp = MCP_Geometric(self.costs, fully_connected=True)
        cumulative, _ = mcp.find_costs([begin], [end])
        if not np.isfinite(cumulative[end]):
            return None
        return self._pulled_tight(mcp.traceback(end))

    def clear_line(self, a: np.ndarray, b: np.ndarray) -> bool:
        """Whether the straight line from `a` to `b` (x, y) crosses only passable cells."""
        return self._clear(self.index(a), self.index(b))

    def _clear(self, a: tuple[int, int], b: tuple[int, int]) -> bool:
        steps = max(abs(b[0] - a[0]), abs(b[1] - a[1]), 1) * 2
        t = np.linspace(0.0, 1.0, steps + 1)
        rows = np.round(a[0] + t * (b[0] - a[0])).astype(int)
        cols = np.round(a[1] + t * (b[1] - a[1])).astype(int)
        return bool(np.isfinite(self.costs[rows, cols]).all())

    def _pulled_tight(self, cells: list[tuple[int, int]]) -> list[tuple[int, int]]:
        kept = [cells[0]]
        i = 0
        while i < len(cells) - 1:
            j = len(cells) - 1
            while j > i + 1 and not self._clear(cells[i], cells[j]):
                j -= 1
            kept.append(cells[j])
            i = j
        return kept

    def _passable_near(self, index: tuple[int, int]) -> tuple[int, int] | None:
        if np.isfinite(self.costs[index]):
            return index
        free = np.argwhere(np.isfinite(self.costs))
        if not len(free):
            return None
        nearest = free[np.argmin(np.sum((free - np.array(index)) ** 2, axis=1))]
        return int(nearest[0]), int(nearest[1])


def _extent(ground: Ground, around: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(low, high) x, y corners of the area to plan in."""
    half = ground.extent
    if half is not None:
        return -half, half
    centres, spans = ground.obstacle_spans()
    points = np.vstack([centres, around]) if len(around) else centres
    span = float(spans.max()) if len(spans) else 0.0
    return points.min(axis=0) - MARGIN - span, points.max(axis=0) + MARGIN + span


class Navigator:
    """Where each creature crawls this frame (`LocomotionStores.creatures.steer`): its
    goal, or the next waypoint of a route around the obstacles between them.

    On a ground without obstacles every creature steers straight at its current goal,
    as the thesis does. With obstacles, a creature whose `navigate` is on (the scene's
    `navigation`, default true) gets a route when its goal changes (`CostGrid`, made
    at the first frame, for the creature's own reach); it steers at each waypoint in
    turn until within `WAYPOINT_RADIUS`, then at the goal. A creature that gets no
    closer to its waypoint for `STUCK_SECONDS` is re-planned from where it is.
    The tentacle_selection system calls `steer` first thing each frame.
    """

    provided_by = "locomotion"

    def __init__(self) -> None:
        self.routes: dict[int, np.ndarray] = {}  # creature row -> waypoints left (k, 3)
        self.planned = np.zeros((0, 3))  # the goal each route was planned for
        self.best = np.zeros(0)  # closest to the current waypoint so far
        self.since = np.zeros(0)  # when `best` last improved
        self.target = np.zeros((0, 3))  # each route's next waypoint (NaN: none), for arrays
        self.survey: Survey | None = None
        self.grids: dict[float, CostGrid] = {}  # by reach, the last KEPT_GRIDS made
        self._ground: Ground | None = None
        self.plans = 0  # routes planned so far (first plans and re-plans)

    def state(self) -> NavigationState:
        """What a snapshot keeps (the grid is remade from the ground)."""
        routes = {row: r.copy() for row, r in self.routes.items()}
        return routes, self.planned.copy(), self.best.copy(), self.since.copy()

    def set_state(self, state: NavigationState) -> None:
        routes, planned, best, since = state
        self.routes = {row: r.copy() for row, r in routes.items()}
        self.planned, self.best, self.since = planned.copy(), best.copy(), since.copy()
        self.target = np.full((len(self.best), 3), np.nan)
        for row, route in self.routes.items():
            self.target[row] = route[0]

    def roster_changed(self, change: RosterChange) -> None:
        """A creature came (no route yet) or went (its route dropped, rows renumbered)."""
        if self._ground is None:
            return  # not started: `_start` sizes everything from the world
        moved = change.moved.get("creatures")
        if moved is not None:
            self.routes = {int(moved[r]): w for r, w in self.routes.items() if moved[r] >= 0}
        self.planned = change.follow(self.planned, "creatures", np.nan)
        self.best = change.follow(self.best, "creatures", np.inf)
        self.since = change.follow(self.since, "creatures", 0.0)
        self.target = change.follow(self.target, "creatures", np.nan)

    def waypoints(self, row: int) -> np.ndarray:
        """(k, 3) the waypoints creature `row` still has to pass (none: straight on)."""
        return self.routes.get(row, np.zeros((0, 3)))

    def steer(self, world: Host) -> None:
        """Set every creature's steer point for this frame (see the class doc)."""
        g = world.resource(LocomotionStores).creatures
        g.steer[:] = g.goal
        ground = ground_of(world)
        if not ground.has_obstacles or not g.has_goal.any():
            return
        if ground is not self._ground:
            self._start(world, ground)
        steering = g.has_goal & g.navigate
        changed = steering & ~np.all(g.goal == self.planned, axis=1)
        mantle = world.transforms.pos[world.creatures.mantle_row]
        for row in np.flatnonzero(changed).tolist():
            self._plan(world, g, row, mantle[row])
        self.planned[~steering] = np.nan
        routed = ~np.isnan(self.target[:, 0])
        for row in np.flatnonzero(routed & ~steering).tolist():  # goal gone or navigation off
            self._drop(row)
        rows = np.flatnonzero(routed & steering)
        if not len(rows):
            return
        distance = np.linalg.norm(mantle[rows, :2] - self.target[rows, :2], axis=1)
        for row in rows[distance < WAYPOINT_RADIUS].tolist():  # events: a waypoint passed
            self._advance(world, row)
        improved = distance < self.best[rows] - PROGRESS
        self.best[rows[improved]] = distance[improved]
        self.since[rows[improved]] = world.time
        stuck = rows[world.time - self.since[rows] > STUCK_SECONDS]
        for row in stuck[~np.isnan(self.target[stuck, 0])].tolist():
            self._plan(world, g, row, mantle[row])
        routed = np.flatnonzero(~np.isnan(self.target[:, 0]))
        g.steer[routed] = self.target[routed]

    def _start(self, world: Host, ground: Ground) -> None:
        n = len(world.creatures)
        self._ground = ground
        self.routes = {}
        self.planned = np.full((n, 3), np.nan)
        self.best = np.full(n, np.inf)
        self.since = np.zeros(n)
        self.target = np.full((n, 3), np.nan)
        g = world.resource(LocomotionStores).creatures
        points = [world.transforms.pos[world.creatures.mantle_row, :2], g.goal[:, :2]]
        self.survey = Survey.of(ground, np.vstack(points))
        self.grids = {}

    def grid_for(self, world: Host, row: int) -> CostGrid | None:
        """The cost grid creature `row` plans on: its reach's (its mantle's radius and
        longest tentacle)."""
        if self.survey is None:
            return None
        lengths = world.tentacles.length[world.tentacles.creature_row == row]
        reach = float(world.creatures.mantle_radius[row]) + float(lengths.max(initial=0.0))
        grid = self.grids.get(reach)
        if grid is None:
            if len(self.grids) >= KEPT_GRIDS:
                del self.grids[next(iter(self.grids))]  # the oldest
            grid = self.grids[reach] = self.survey.grid(reach)
        return grid

    def _plan(self, world: Host, g: CreatureGaitStore, row: int, mantle: np.ndarray) -> None:
        self.planned[row] = g.goal[row]
        self._drop(row)
        self._reset_progress(world, row)
        grid = self.grid_for(world, row)
        if grid is None or grid.clear_line(mantle[:2], g.goal[row, :2]):
            return  # the goal is in plain sight
        route = grid.route(mantle[:2], g.goal[row, :2])
        self.plans += 1
        if route is None or len(route) < 2:
            return  # nowhere to go around: straight at the goal, as without navigation
        assert self._ground is not None
        self._set(row, np.column_stack([route[:-1], self._ground.surface(route[:-1])]))

    def _advance(self, world: Host, row: int) -> None:
        self._set(row, self.routes[row][1:])
        self._reset_progress(world, row)

    def _set(self, row: int, route: np.ndarray) -> None:
        """Creature `row` follows `route` (waypoints; none: straight at its goal)."""
        if not len(route):
            self._drop(row)
            return
        self.routes[row] = route
        self.target[row] = route[0]

    def _drop(self, row: int) -> None:
        self.routes.pop(row, None)
        self.target[row] = np.nan

    def _reset_progress(self, world: Host, row: int) -> None:
        self.best[row] = np.inf
        self.since[row] = world.time
