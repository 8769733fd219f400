"""Locomotion in the sandbox: goal rings and paths drawn, goals set and removed by clicks.

The locomotion plugin's sandbox entries (its build) call these. Each creature's path is a ring and
a short post at every goal and the legs between them, in a light tint of the
creature's colour, plus the leg from the creature to its current goal, which moves
with it, and (with obstacles) the path navigation planned around them, through its
waypoints. The rings and legs between goals are rebuilt only when a goal changes
(`GoalBook.version`); the moving legs are one vectorised pass a frame.

Mouse (the plugin's `Clicks` entry): a left click on the ground sets the selected creature's goal
(several selected: one goal each, in formation around the point), shift-click appends
one to the path, a right click inside a goal's ring removes it.
Reads: `GoalBook` (paths, positions), `Goal` radii, the Transform store.
Writes: goals, through `GoalBook`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.components import Creature, Transform
from ecs_tentacles.ground import ground_of
from ecs_tentacles.locomotion.components import Goal
from ecs_tentacles.locomotion.formations import FormationChoice, formation_goals
from ecs_tentacles.locomotion.goals import GoalBook
from ecs_tentacles.locomotion.navigation import Navigator
from ecs_tentacles.render.registries import Click, RenderView
from ecs_tentacles.render.rings import CIRCLE, draped, line_segments

if TYPE_CHECKING:
    from ecs_tentacles.host import Host

GOALS = "locomotion.goals"  # the key of the cached geometry in the renderer's state
ALL_PATHS = 8  # up to this many creatures every path is drawn in full
FADED = 0.35  # how much of its colour a crowd creature's ring keeps
FADE_TO = np.array([0.62, 0.56, 0.44])  # toward the ground's colour
LIFT = 0.005  # metres above the ground the lines are drawn


@dataclass
class GoalLines:
    """Rings, posts and legs between goals of one world at one `GoalBook.version`."""

    world: Host
    # (the goal book's version, the selection) it was made for
    version: tuple[int, int | None, tuple[int, ...]]
    fixed: np.ndarray  # line-list vertices (2n, 7)
    leader_rows: np.ndarray  # Transform rows of the creatures that have a goal
    leader_ends: np.ndarray  # (n, 3) their current goals
    leader_colours: np.ndarray  # (n, 4)


def goal_lines(world: Host, view: RenderView) -> GoalLines:
    """Every path's fixed geometry, from the goal book as it is now. In a crowd (more
    than `ALL_PATHS` creatures) only the selected creatures' paths are drawn in full and
    led to from the creature; the others' rings are faded, without legs, so a crowd's
    picture is not a starburst of lines."""
    book = world.resource(GoalBook)
    fixed: list[np.ndarray] = []
    leaders, firsts, colours = [], [], []
    crowd = len(view.creatures) > ALL_PATHS
    chosen = set(view.selection) | ({view.selected} if view.selected is not None else set())
    for entity in view.creatures:
        goals = book.path(entity)
        if not goals:
            continue
        shown = not crowd or entity in chosen
        colour = np.append(view.colours[entity] * 0.6 + 0.4, 1.0)
        if not shown:
            colour = np.append(colour[:3] * FADED + (1.0 - FADED) * FADE_TO, 1.0)
        points = book.positions(entity) + [0, 0, LIFT]
        if shown:
            fixed.append(line_segments(points, colour))
        ground = ground_of(world)
        for goal, point in zip(goals if shown else goals[:1], points, strict=False):
            radius = world.component(goal, Goal).radius
            fixed.append(line_segments(draped(point + radius * CIRCLE, ground, LIFT), colour))
            if shown:
                fixed.append(line_segments(np.array([point, point + [0, 0, 0.3]]), colour))
        if not shown:
            continue
        leaders.append(world.component(entity, Transform).row)
        firsts.append(points[0])
        colours.append(colour)
    return GoalLines(
        world,
        (int(book.version), view.selected, view.selection),
        np.vstack(fixed) if fixed else np.zeros((0, 7)),
        np.array(leaders, dtype=np.int64),
        np.array(firsts).reshape(-1, 3),
        np.array(colours).reshape(-1, 4),
    )


def path_lines(world: Host, view: RenderView) -> list[np.ndarray]:
    """This frame's goal rings and paths (line-list vertices), the fixed part cached."""
    cached = view.state.get(GOALS)
    version = (int(world.resource(GoalBook).version), view.selected, view.selection)
    if not isinstance(cached, GoalLines) or cached.world is not world or cached.version != version:
        cached = view.state[GOALS] = goal_lines(world, view)
    # each creature's leg to its current goal moves with it: one vectorised pass
    start = view.pos[cached.leader_rows]
    start[:, 2] = ground_of(world).height(start[:, :2]) + LIFT
    leaders = np.empty((2 * len(cached.leader_rows), 7))
    leaders[0::2, :3] = start
    leaders[1::2, :3] = cached.leader_ends
    leaders[:, 3:] = np.repeat(cached.leader_colours, 2, axis=0)
    return [cached.fixed, leaders, *_routes(world, cached, start)]


def _routes(world: Host, cached: GoalLines, start: np.ndarray) -> list[np.ndarray]:
    """The legs of the paths navigation planned around obstacles: from each creature
    through its waypoints (a bright dashed-looking polyline over its straight leg)."""
    navigation = world.resource(Navigator)
    if not navigation.routes or not len(cached.leader_rows):
        return []
    mantle_rows = world.creatures.mantle_row
    lines = []
    for i, row in enumerate(cached.leader_rows.tolist()):
        creature = np.flatnonzero(mantle_rows == row)
        if not len(creature):
            continue
        route = navigation.waypoints(int(creature[0]))
        if not len(route):
            continue
        points = np.vstack([start[i], route + [0, 0, LIFT], cached.leader_ends[i]])
        colour = np.append(np.minimum(cached.leader_colours[i, :3] * 1.3 + 0.2, 1.0), 1.0)
        lines.append(line_segments(points, colour))
    return lines


def goal_points(world: Host) -> np.ndarray:
    """Every goal's position (n, 3), for the camera's "frame all"."""
    book = world.resource(GoalBook)
    paths = [book.positions(entity) for entity, _ in world.query(Creature)]
    return np.vstack(paths) if paths else np.zeros((0, 3))


def remove_goal_at(world: Host, point: np.ndarray) -> int | None:
    """Remove the goal whose ring contains `point` (the nearest one); its entity."""
    best, best_distance = None, np.inf
    for entity, goal in world.query(Goal):
        distance = float(np.linalg.norm(goal.position[:2] - point[:2]))
        if distance <= goal.radius and distance < best_distance:
            best, best_distance = entity, distance
    if best is not None:
        world.resource(GoalBook).remove(best)
    return best


def click_goal(world: Host, click: Click) -> bool:
    """Set (left), append (shift-left) or remove (right) a goal; True if the click was one.

    With several creatures selected each gets its own goal in the chosen formation
    around the point (`ecs_tentacles.locomotion.formations`)."""
    if click.ground is None:
        return False
    chosen = click.chosen
    if click.button == "left" and click.creature is None and chosen:
        book = world.resource(GoalBook)
        shape = world.resource(FormationChoice).shape
        goals = formation_goals(world, chosen, click.ground[:2], shape)
        for creature, goal in zip(chosen, goals, strict=True):
            (book.append if click.shift else book.set)(creature, goal.tolist())
        return True
    if click.button == "right":
        return remove_goal_at(world, click.ground) is not None
    return False
