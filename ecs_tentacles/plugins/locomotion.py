"""The locomotion plugin: goal paths, gait and the action queues that crawl toward goals.

Scene keys: a creature's `goals` and `locomotion` (`assets/schema/plugins/locomotion.json`).
Resources: `world.goals` (GoalBook) and `world.locomotion` (parameters at run time).
Systems: goals, tentacle_selection (stage decide), action_queue, motor_targets (act).
"""

from __future__ import annotations

import copy
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

from ecs_tentacles.components import Creature, Goal, Tentacle
from ecs_tentacles.locomotion.actions import STRENGTH, ActionQueue, Kind
from ecs_tentacles.locomotion.goals import GoalBook
from ecs_tentacles.locomotion.params import Locomotion
from ecs_tentacles.plugin import Plugin
from ecs_tentacles.scene.parameters import apply_parameters
from ecs_tentacles.scene.validate import fragment
from ecs_tentacles.system import System

if TYPE_CHECKING:
    from ecs_tentacles.world import World

_FRAGMENT = fragment("locomotion")


class LocomotionPlugin(Plugin):
    name = "locomotion"
    description = "goal-directed crawling: goal paths, gait, action queues, motor targets"
    creature_schema = _FRAGMENT["creature"]
    defs = _FRAGMENT["$defs"]

    def resources(self, world: World) -> dict[str, Any]:
        return {"goals": GoalBook(world), "locomotion": Locomotion(world)}

    def build_creature(self, world: World, creature: int, spec: Mapping[str, Any]) -> None:
        row = world.component(creature, Creature).row
        apply_parameters(world, "locomotion", spec["locomotion"], creatures=row)
        for entity in world.component(creature, Creature).tentacles:
            world.add_component(entity, ActionQueue())
            world.tentacles.action_strength[world.component(entity, Tentacle).row] = STRENGTH[
                Kind.IDLE
            ]
        for goal in spec["goals"]:
            point = list(goal["position"]) + ([0.0] if len(goal["position"]) == 2 else [])
            world.goals.append(creature, point, goal["radius"])

    def systems(self) -> list[System]:
        from ecs_tentacles.systems.action_queue import ActionQueueSystem
        from ecs_tentacles.systems.goals import Goals
        from ecs_tentacles.systems.motor_targets import MotorTargets
        from ecs_tentacles.systems.tentacle_selection import TentacleSelection

        return [Goals(), TentacleSelection(), ActionQueueSystem(), MotorTargets()]

    def snapshot(self, world: World) -> Any:
        goals = {
            entity: [
                (world.component(g, Goal).position.copy(), world.component(g, Goal).radius)
                for g in world.goals.path(entity)
            ]
            for entity, _ in world.query(Creature)
        }
        queues = {e: copy.deepcopy(q.pending) for e, q in world.query(ActionQueue)}
        return goals, queues

    def restore(self, world: World, state: Any) -> None:
        goals, queues = state
        for entity, path in goals.items():
            world.goals.clear(entity)
            for position, radius in path:
                world.goals.append(entity, position.tolist(), radius)
        for entity, queue in world.query(ActionQueue):
            queue.pending = copy.deepcopy(queues[entity])
