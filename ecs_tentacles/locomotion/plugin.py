"""The locomotion plugin: goal paths, gait and the action queues that crawl toward goals.

Scene keys: a creature's `goals` and `locomotion` (`locomotion.schema.json` beside this file).
Resources: `GoalBook` (goal paths) and `Locomotion` (parameters at run time), by type:
`world.resource(GoalBook)`.
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
    from ecs_tentacles.host import Host

_FRAGMENT = fragment("ecs_tentacles.locomotion", "locomotion")


class LocomotionPlugin(Plugin):
    name = "locomotion"
    description = "goal-directed crawling: goal paths, gait, action queues, motor targets"
    creature_schema = _FRAGMENT["creature"]
    defs = _FRAGMENT["$defs"]

    def resources(self, world: Host) -> list[object]:
        return [GoalBook(world), Locomotion(world)]

    def build_creature(self, world: Host, creature: int, spec: Mapping[str, Any]) -> None:
        row = world.component(creature, Creature).row
        apply_parameters(world, "locomotion", spec["locomotion"], creatures=row)
        for entity in world.component(creature, Creature).tentacles:
            world.add_component(entity, ActionQueue())
            world.tentacles.action_strength[world.component(entity, Tentacle).row] = STRENGTH[
                Kind.IDLE
            ]
        for goal in spec["goals"]:
            point = list(goal["position"]) + ([0.0] if len(goal["position"]) == 2 else [])
            world.resource(GoalBook).append(creature, point, goal["radius"])

    def systems(self) -> list[System]:
        from ecs_tentacles.systems.locomotion.action_queue import ActionQueueSystem
        from ecs_tentacles.systems.locomotion.goals import Goals
        from ecs_tentacles.systems.locomotion.motor_targets import MotorTargets
        from ecs_tentacles.systems.locomotion.tentacle_selection import TentacleSelection

        return [Goals(), TentacleSelection(), ActionQueueSystem(), MotorTargets()]

    def snapshot(self, world: Host) -> Any:
        goals = {
            entity: [
                (world.component(g, Goal).position.copy(), world.component(g, Goal).radius)
                for g in world.resource(GoalBook).path(entity)
            ]
            for entity, _ in world.query(Creature)
        }
        queues = {e: copy.deepcopy(q.pending) for e, q in world.query(ActionQueue)}
        return goals, queues

    def restore(self, world: Host, state: Any) -> None:
        goals, queues = state
        for entity, path in goals.items():
            world.resource(GoalBook).clear(entity)
            for position, radius in path:
                world.resource(GoalBook).append(entity, position.tolist(), radius)
        for entity, queue in world.query(ActionQueue):
            queue.pending = copy.deepcopy(queues[entity])
