"""Navigation: creatures reach goals behind obstacles by paths around them; without
it they crawl straight and stay stuck behind the wall."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

from ecs_tentacles.components import Creature
from ecs_tentacles.ground import ground_of
from ecs_tentacles.locomotion.navigation import KERNELS, STUCK_SECONDS, CostGrid, Navigator, Survey
from ecs_tentacles.locomotion.render import path_lines
from ecs_tentacles.render.registries import RenderView
from ecs_tentacles.terrain import presets
from ecs_tentacles.terrain.ground import TerrainGround
from ecs_tentacles.terrain.scene_ground import build_ground
from ecs_tentacles.terrain.shapes import Solid
from ecs_tentacles.world import World

WALL = {"shape": "box", "position": [-1.6, 0, 0.3], "size": [4.8, 0.2, 0.6]}  # ends at x = 0.8


def behind_the_wall(navigation: bool) -> dict[str, Any]:
    creature = {"name": "o", "position": [0, -1.6], "goals": [{"position": [0, 1.6]}]}
    if not navigation:
        creature["navigation"] = False
    return {"version": 1, "terrain": {"obstacles": [WALL]}, "creatures": [creature]}


@pytest.mark.parametrize("navigation", [True, False], ids=["navigation on", "navigation off"])
def test_a_goal_behind_a_wall_is_reached_only_by_navigation(
    make_world: Callable[..., World], navigation: bool
) -> None:
    world = make_world(behind_the_wall(navigation))
    reached: list[float] = []
    world.events.on("goal_reached", lambda **_: reached.append(world.time))
    anchors: list[np.ndarray] = []
    world.events.on("sucker_attached", lambda **kw: anchors.append(kw["anchor"]))
    # navigating, it reaches the goal in 44.5 s, already 0.5 m past the wall at 30 s:
    # without, 30 s shows it held behind the wall (its mantle stays at y = -0.6 to 50 s)
    while world.time < (50.0 if navigation else 30.0) and not reached:
        world.step()
    mantle = world.transforms.pos[world.creatures.mantle_row[0]]
    if navigation:
        assert reached and mantle[1] > 0.5, mantle  # around the wall's end, at the goal
    else:
        assert not reached and mantle[1] < -0.3, mantle  # still pressed against the wall
        # pressed against it, the suckers grip the wall's face too, not only the ground
        normals = ground_of(world).normal(np.array(anchors))
        assert (np.abs(normals[:, 2]) < 0.5).sum() >= 1
    assert world.physics.health.recoveries == 0


def test_the_sandbox_can_draw_the_planned_path(make_world: Callable[..., World]) -> None:
    world = make_world(behind_the_wall(True))
    world.step()
    route = world.resource(Navigator).waypoints(0)
    assert len(route) >= 1
    assert (route[:, 0] > 0.8).all()  # every waypoint is past the wall's end
    creature = world.creature("o")
    view = RenderView(
        world.transforms.pos.copy(),
        world.transforms.quat.copy(),
        [creature],
        {creature: np.array([0.8, 0.3, 0.2])},
    )
    lines = np.concatenate([np.asarray(seg).reshape(-1, 7) for seg in path_lines(world, view)])
    for waypoint in route:  # a drawn vertex at every waypoint
        assert np.min(np.linalg.norm(lines[:, :2] - waypoint[:2], axis=1)) < 1e-6


def test_routes_go_around_and_none_when_walled_in() -> None:
    wall = Solid("box", np.array([0.0, 0.0, 0.5]), np.eye(3), (2.0, 0.1, 0.5))
    grid = CostGrid.of(TerrainGround(solids=(wall,)), 0.5, np.array([[0.0, -3.0], [0.0, 3.0]]))
    assert grid is not None
    route = grid.route(np.array([0.0, -3.0]), np.array([0.0, 3.0]))
    assert route is not None and route[-1].tolist() == [0.0, 3.0]
    assert np.abs(route[:-1, 0]).min() > 2.0  # around one end of the wall, not through it
    ring = tuple(
        Solid("box", np.array([x, y, 0.5]), np.eye(3), (sx, sy, 0.5))
        for x, y, sx, sy in (
            (0, 2, 2.1, 0.1),
            (0, -2, 2.1, 0.1),
            (2, 0, 0.1, 2.1),
            (-2, 0, 0.1, 2.1),
        )
    )
    inside = CostGrid.of(TerrainGround(solids=ring), 0.3, np.array([[0.0, 0.0], [5.0, 5.0]]))
    assert inside is not None
    assert inside.route(np.array([0.0, 0.0]), np.array([5.0, 5.0])) is None
    assert CostGrid.of(TerrainGround(), 0.5, np.zeros((1, 2))) is None  # nothing to steer around


def test_a_creature_stuck_on_its_way_is_planned_again(make_world: Callable[..., World]) -> None:
    world = make_world(behind_the_wall(True))
    world.step()
    navigator = world.resource(Navigator)
    assert navigator.plans == 1 and len(navigator.waypoints(0))
    world.physics.frozen[:] = True  # held in place: no progress toward the waypoint
    while world.time < 1.0 + STUCK_SECONDS:
        world.step()
    assert navigator.plans == 2  # once, not every frame
    world.physics.frozen[:] = False


def test_a_creature_spawned_after_the_last_one_left_is_routed(
    make_world: Callable[..., World],
) -> None:
    world = make_world(behind_the_wall(True))
    world.step()
    world.despawn(world.creature("o"))  # the world is empty, its navigation started
    world.step()
    entity = world.spawn({"name": "p", "goals": [{"position": [0, 1.6]}]}, position=(0, -1.6))
    world.step(2)
    route = world.resource(Navigator).waypoints(world.component(entity, Creature).row)
    assert len(route) and (route[:, 0] > 0.8).all()  # around the wall's end, as the first


def test_a_route_does_not_depend_on_who_else_is_in_the_world(
    make_world: Callable[..., World],
) -> None:
    """Each creature plans on the grid of its own reach: the cost grid was made for the
    largest creature's, so a long-armed creature elsewhere changed a small one's route
    (and a shard of a bake, holding some of a crowd, planned otherwise than the whole
    crowd: its take differed from the local bake's)."""
    alone = behind_the_wall(True)
    small = alone["creatures"][0]
    small["tentacles"] = {"count": 4, "links": 4, "link_length": 0.05}
    big = {"name": "big", "position": [6, 6], "tentacles": {"links": 12, "link_length": 0.12}}
    crowd = {**alone, "creatures": [small, big]}
    routes = []
    for scene in (alone, crowd):
        world = make_world(scene)
        world.step()
        routes.append(
            world.resource(Navigator).waypoints(world.component(world.creature("o"), Creature).row)
        )
    assert len(routes[0]) >= 1
    np.testing.assert_array_equal(routes[0], routes[1])


def box(x: float, y: float, sx: float, sy: float) -> dict[str, Any]:
    return {"shape": "box", "position": [x, y, 0.0], "size": [sx, sy, 3.0]}


@pytest.mark.parametrize("ground", ["rocky", "walls"])
def test_routes_by_numba_are_scikit_images_bit_for_bit(
    ground: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Every route numba plans (`route_kernels.route_cells`) has the waypoints of the
    numpy path's (scikit-image's `MCP_Geometric` and `_pulled_tight`, the planner
    before the kernel), from each start to every goal, one of them penned in (no route:
    all the ground searched, the heap grown and shrunk to empty): on rocky ground (a
    noise heightfield and boulders) and on flat ground between walls, where most cells
    cost the same and many paths tie (a cell keeps its first predecessor unless a
    strictly cheaper one comes: taking the first of equals instead moves waypoints)."""
    assert KERNELS.get() is not None  # numba comes with the dev extra
    rng = np.random.default_rng(7)
    crowd = rng.uniform(-6.0, 6.0, size=(64, 2))  # the rocks' count follows the crowd's
    starts = crowd[:8]
    if ground == "rocky":
        pen = (4.0, 2.8)
        terrain = presets.rocky(crowd, 0.6, seed=3)
    else:
        pen = (0.0, 5.6)
        walls = [box(0.0, 0.0, 4.1, 0.1), box(-3.0, -3.0, 0.1, 3.0), box(3.0, -3.0, 0.1, 3.0)]
        terrain = {"obstacles": [*walls, box(0.0, 3.5, 3.0, 0.1)]}
    x, y = pen
    penned = [box(x, y + 1.2, 1.2, 0.1), box(x, y - 1.2, 1.2, 0.1)]
    penned += [box(x - 1.1, y, 0.1, 1.3), box(x + 1.1, y, 0.1, 1.3)]
    terrain["obstacles"] = [*terrain["obstacles"], *penned]  # type: ignore[misc]
    survey = Survey.of(build_ground(terrain, None), starts)  # type: ignore[arg-type]
    assert survey is not None
    grids = [survey.grid(reach) for reach in (0.55, 0.66)]
    goals = np.vstack([-starts[::2], [pen]])  # across the middle, and in the pen
    planned = {}
    for backend in ("auto", "numpy"):
        monkeypatch.setattr(KERNELS, "backend", backend)
        planned[backend] = [
            grid.route(start, goal) for grid in grids for start in starts for goal in goals
        ]
    walled_in = sum(route is None for route in planned["numpy"])
    bends = sum(route is not None and len(route) > 1 for route in planned["numpy"])
    assert walled_in == 2 * len(starts) and bends >= 10, (walled_in, bends)
    for fast, reference in zip(planned["auto"], planned["numpy"], strict=True):
        if reference is None:
            assert fast is None
        else:
            assert fast is not None
            np.testing.assert_array_equal(fast, reference)
