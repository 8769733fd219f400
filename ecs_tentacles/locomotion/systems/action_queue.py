"""action_queue: advances every tentacle's action timer and starts the next action.

An interrupted tentacle (`ActionQueues.interrupt`: tentacle_selection starting or
aborting a drive, or a script) moves on at once, whatever its timer. The tentacles of
creatures the level of detail replays (KINEMATIC, as the last frame decided) move on
to nothing: their actions pause, and go on (an overdue one ends) once promoted.

Reads: locomotion's tentacle store (timer, duration, action, interrupted),
TentacleStore (tip sucker), Sucker store (attached: an attach action waits for its
sucker, up to ATTACH_PATIENCE times its duration), ActionQueues. Writes: locomotion's
tentacle store (current action, timer, duration, angle, strength, orient,
interrupted cleared; driving and mode go back to idle when a queue runs dry).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.locomotion.actions import ATTACH_PATIENCE, STRENGTH, ActionQueues, Kind, Mode
from ecs_tentacles.locomotion.stores import LocomotionStores
from ecs_tentacles.numeric.optional_kernels import OptionalKernels
from ecs_tentacles.system import System

if TYPE_CHECKING:
    from ecs_tentacles.host import Host
    from ecs_tentacles.roster_change import RosterChange

KERNELS = OptionalKernels("ecs_tentacles.locomotion.action_kernels", "ECS_TENTACLES_ACTIONS")
TIME_EPSILON = 1e-9  # sums of frame durations fall a hair short of whole durations
ATTACH = int(Kind.ATTACH)


class ActionQueueSystem(System):
    name = "action_queue"
    stage = "act"
    reads = ("action_queues", "suckers.attached", "tentacles.tip_sucker", "tentacles.creature_row")
    writes = (
        "locomotion.tentacles.action",
        "locomotion.tentacles.timer",
        "locomotion.tentacles.duration",
        "locomotion.tentacles.action_angle",
        "locomotion.tentacles.action_strength",
        "locomotion.tentacles.orient",
        "locomotion.tentacles.interrupted",
        "locomotion.tentacles.driving",
        "locomotion.tentacles.mode",
    )

    def setup(self, world: Host) -> None:
        self.queues = ActionQueues(world)
        self.strokes = world.resource(LocomotionStores).tentacles

    def roster_changed(self, world: Host, change: RosterChange) -> None:
        self.queues.roster_changed(world, change)  # the queues by tentacle row

    def process(self, world: Host, dt: float) -> None:
        t = self.strokes
        if not len(t):
            return
        replayed = world.physics.kinematic_creatures(len(world.creatures))
        fast = KERNELS.get()
        if fast is not None:  # the same rows and timers in one pass
            tentacles = world.tentacles
            rows = fast.due(t.timer, t.duration, t.action, t.interrupted, tentacles.creature_row,
                            replayed, world.suckers.attached, tentacles.tip_sucker, float(dt),
                            TIME_EPSILON, ATTACH, float(ATTACH_PATIENCE))  # fmt: skip
            for row in rows:
                self._advance(world, int(row))
            return
        t.timer += dt
        done = t.timer >= t.duration - TIME_EPSILON
        attaching = t.action == ATTACH
        if attaching.any():
            gripped = world.suckers.attached[world.tentacles.tip_sucker]
            patience = ATTACH_PATIENCE * t.duration - TIME_EPSILON
            done &= ~attaching | gripped | (t.timer >= patience)
        interrupted = t.interrupted
        if interrupted.any():
            done |= interrupted
        if replayed.any():  # their actions pause (an interruption waits): the clip carries them
            done &= ~replayed[world.tentacles.creature_row]
        interrupted[done] = False
        for row in np.flatnonzero(done):
            self._advance(world, int(row))

    def _advance(self, world: Host, row: int) -> None:
        t = self.strokes
        queue = self.queues[row]  # (its methods make no deque for a queue never used)
        t.timer[row] = 0.0
        if not queue:
            t.action[row] = Kind.IDLE
            t.duration[row] = np.inf
            t.action_angle[row] = 0.0
            t.action_strength[row] = STRENGTH[Kind.IDLE]
            t.orient[row] = 0.0
            t.driving[row] = False
            t.mode[row] = Mode.NONE
            return
        action = queue.popleft()
        t.action[row] = action.kind
        t.duration[row] = action.duration
        t.action_angle[row] = action.angle
        t.action_strength[row] = action.strength
        if action.kind == Kind.ORIENT:
            t.orient[row] = action.angle
        elif action.kind == Kind.SETTLE:
            t.orient[row] = 0.0
