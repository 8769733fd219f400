"""The locomotion feature's stores: per-tentacle strokes and per-creature gaits.

Rows line up with the core stores: row `k` of `LocomotionStores.tentacles` is the
tentacle in row `k` of `world.tentacles` (the body: links, base, tip sucker, length),
row `c` of `.creatures` the creature in row `c` of `world.creatures`. The locomotion
plugin adds them as it builds each creature, so core stores hold the body only.
Registered as `locomotion.tentacles` and `locomotion.creatures` (`world.stores`):
systems declare `"locomotion.tentacles.action"` and the like.

    loco = world.resource(LocomotionStores)
    loco.tentacles.speed[rows] = 1.5      # what `world.resource(Locomotion).set` writes
    loco.creatures.has_goal               # which creatures crawl toward a goal
"""

from __future__ import annotations

import numpy as np

from ecs_tentacles.store import ArrayStore, Field


class TentacleGaitStore(ArrayStore):
    """Per tentacle: locomotion parameters and the current action, as arrays.

    Parameters (`speed` ... `writhe`) are what scripts and the HUD change at run time.
    The current action (`action`, `timer`, `duration`, `action_angle`,
    `action_strength`) is the one last taken from the tentacle's `ActionQueue`;
    `interrupted` ends it early (`ecs_tentacles.locomotion.actions.ActionQueues`).
    """

    # parameters
    lines_up_with = "tentacles"

    speed = Field(default=1.0)
    target_angle = Field()
    wave_amplitude = Field()
    wave_frequency = Field()
    wavelength = Field(default=1.0)
    writhe = Field()
    phase = Field()
    # the current action
    action = Field(dtype=np.int64)
    timer = Field()
    duration = Field(default=np.inf)
    action_angle = Field()
    action_strength = Field(default=1.0)
    orient = Field()  # sweep (radians) toward the goal line, held through a stroke
    interrupted = Field(dtype=np.bool_, default=False)  # ends this frame (ActionQueues.interrupt)
    mode = Field(dtype=np.int64)  # 0 idle, 1 push, 2 pull
    driving = Field(dtype=np.bool_, default=False)
    started = Field(default=-np.inf)  # time the current drive began


class CreatureGaitStore(ArrayStore):
    """Per creature: gait, speed, drivers, sucker release thresholds, the current goal and
    where it steers (navigation, avoidance)."""

    lines_up_with = "creatures"

    gait = Field(dtype=np.int64)  # index into the schema's gait choices (scene.parameters)
    speed = Field(default=1.0)
    drivers = Field(dtype=np.int64, default=1)
    release_stretch = Field()
    release_reach = Field()
    next_driver = Field(dtype=np.int64)  # cyclic: whose turn is next
    last_start = Field(default=-np.inf)  # coordinated: when the last drive began
    has_goal = Field(dtype=np.bool_, default=False)
    goal = Field((3,))  # the current goal's position (valid when has_goal)
    goal_radius = Field()
    navigate = Field(dtype=np.bool_, default=True)  # plan paths around obstacles (navigation)
    steer = Field((3,))  # where it crawls this frame: the goal or a waypoint (navigation)
    avoid = Field(dtype=np.bool_, default=True)  # steers around other creatures (avoidance)
    avoidance = Field((2,))  # the avoidance term this frame, in ground xy (0: straight on)


class LocomotionStores:
    """`world.resource(LocomotionStores)`: the locomotion columns of tentacles and creatures."""

    provided_by = "locomotion"  # the plugin that makes it (named by `world.resource` errors)

    def __init__(self) -> None:
        self.tentacles = TentacleGaitStore()
        self.creatures = CreatureGaitStore()
