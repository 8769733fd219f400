"""What locomotion adds to the generic outputs (the locomotion plugin's output hooks).

- take track `goals` (points): every goal a creature had during the recording, where
  it was, and whether it was still in the creature's path at each frame;
- shard reach: how far a creature may crawl during a bake (`CRAWL_SPEED` x its
  `locomotion.speed` x the bake's seconds), straight toward its first goal when that
  is farther than it can crawl, anywhere within that distance otherwise;
- run summary: goals reached and goals left;
- take sizes: what the goals track will hold, from a scene (`goal_sizes`).
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.cli.registries import RunSummary
from ecs_tentacles.components import Creature
from ecs_tentacles.distributed.registries import Reach
from ecs_tentacles.locomotion.goals import GoalBook
from ecs_tentacles.scene.spec import as_spec
from ecs_tentacles.take.registries import PointsFrame, TrackSource
from ecs_tentacles.take.tracks import TakeTrack, TrackSize

if TYPE_CHECKING:
    from ecs_tentacles.host import Host

GOALS = TakeTrack("goals", "points", ("goal_pos", "goal_active"), "goals", "goal")
CRAWL_SPEED = 0.25  # m/s per unit of `locomotion.speed`: twice the fastest crawl measured


def goal_points(world: Host) -> PointsFrame:
    """The live goals: each goal entity, its owner, its order in the path, where it is
    (arrays the goal book keeps while no goal changes: no per-goal work per frame)."""
    table = world.resource(GoalBook).table()
    return PointsFrame(
        keys=table.keys,
        creatures=table.owners,
        order=table.orders,
        positions=table.positions,
        radii=table.radii,
    )


GOAL_TRACK = TrackSource(GOALS, goal_points)


def goal_sizes(scene: Mapping[str, object]) -> list[TrackSize]:
    """The goals track of a take of `scene` (defaults filled in), as far as the scene
    says: its goals, each live or not every frame (a byte), where it is (12 bytes) and
    its header entry once. Goals added while baking are counted by `Take.save`."""
    goals = fixed = 0
    creatures = scene["creatures"]
    if not isinstance(creatures, list):
        raise TypeError("a scene's creatures are a list")
    for c, creature in enumerate(creatures):
        name = f"{creature.get('name', f'creature_{c}')}/goals/goal"
        n = len(creature["goals"])
        entry = {"creature": c, "name": name, "radius": 0}  # '{"creature":0,...}' and a comma
        each = 3 * 4 + len(json.dumps(entry, separators=(",", ":"))) - 1 + 1
        radii = sum(len(repr(float(goal["radius"]))) for goal in creature["goals"])
        fixed += n * each + sum(len(str(k)) for k in range(n)) + radii
        goals += n
    return [TrackSize("goals", goals, 1, fixed)] if goals else []


def crawl_reach(creature: Mapping[str, object], seconds: float) -> Reach:
    """Where a creature (scene entry, defaults in) may crawl in `seconds`, beyond its body."""
    locomotion, goals = creature["locomotion"], creature["goals"]
    if not isinstance(locomotion, Mapping) or not isinstance(goals, list):
        raise TypeError("a creature's locomotion and goals are filled in by the validator")
    travel = CRAWL_SPEED * locomotion["speed"] * seconds
    if goals:
        start = np.asarray(as_spec(creature)["position"][:2], dtype=np.float64)
        towards = np.asarray(goals[0]["position"][:2], dtype=np.float64) - start
        length = float(np.linalg.norm(towards))
        if length >= travel:  # it heads straight for the goal all the bake
            x, y = (towards * (travel / length)).tolist()
            return Reach(towards=(x, y))
    return Reach(radius=travel)


def goal_summary(world: Host) -> RunSummary:
    """Goals reached so far and goals still in every creature's path."""
    reached = int(world.events.counts["goal_reached"])
    book = world.resource(GoalBook)
    left = int(sum(len(book.path(e)) for e, _ in world.query(Creature)))
    return RunSummary(
        {"goals_reached": reached, "goals_left": left}, f"goals reached {reached}, left {left}"
    )
