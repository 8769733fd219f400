"""wander: a creature with no goal left gets a random goal near where it is.

    "plugins": {"wander": {"radius": 1.0}}

Every `interval` seconds the `wander` system (stage decide) gives each creature that
has no goal a new one, at a random point between `radius` / 2 and `radius` from its
mantle, so it always has somewhere to crawl. The draws come from one generator per
creature (`creature_rng` of the world's seed and the creature's name): a run repeats
exactly, and a creature draws the same goals whichever other creatures exist.

Reads: CreatureStore (has_goal, mantle_row), Transform store (mantle positions).
Writes: goals, through `travel(world).send` (`ecs_tentacles.behaviour`; only for
creatures that have none).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.behaviour import DestinationSystem, travel
from ecs_tentacles.creatures.body import creature_rng
from ecs_tentacles.plugin import Plugin, Problem
from ecs_tentacles.scene.defaults import plugin_config
from ecs_tentacles.system import System
from ecs_tentacles_examples import farther_than_reach, number, replanning, send_goals, settings

if TYPE_CHECKING:
    from ecs_tentacles.host import Host
    from ecs_tentacles.roster_change import RosterChange


class Wander(DestinationSystem):
    """Idle creatures get a random goal within `radius` of their mantle."""

    name = "wander"
    reads = (
        "locomotion.creatures.has_goal",
        "transforms.pos",
        "creatures.entity",
        "creatures.mantle_row",
    )
    state_attributes = ("streams",)  # each creature's generator: snapshots repeat exactly

    def __init__(self, radius: float, interval: float, goal_radius: float):
        self.radius = radius
        self.interval = interval
        self.goal_radius = goal_radius
        self.every = 1
        self.streams: list[np.random.Generator] = []  # by creature row

    def setup(self, world: Host) -> None:
        self.every = max(1, round(self.interval * world.settings.fps))
        creatures = world.creatures
        self.streams = [
            creature_rng(world.seed, world.creature_name(int(creatures.entity[row])) + ":wander")
            for row in range(creatures.count)
        ]

    def roster_changed(self, world: Host, change: RosterChange) -> None:
        if change.spawned:  # its own stream, as if it had been in the scene
            name = world.creature_name(change.creature)
            self.streams.append(creature_rng(world.seed, name + ":wander"))
        else:
            keep = change.moved["creatures"] >= 0
            self.streams = [s for s, k in zip(self.streams, keep, strict=True) if k]

    def process(self, world: Host, dt: float) -> None:
        if world.frame % self.every:
            return
        creatures = world.creatures
        idle = np.flatnonzero(~travel(world).going(world))
        if not len(idle):
            return
        # two uniform draws per idle creature, each from its own stream
        draws = np.array([self.streams[row].random(2) for row in idle])
        angle = 2 * np.pi * draws[:, 0]
        distance = self.radius * np.sqrt(0.25 + 0.75 * draws[:, 1])  # uniform in the ring
        mantles = world.transforms.pos[creatures.mantle_row[idle], :2]
        goals = mantles + distance[:, None] * np.column_stack([np.cos(angle), np.sin(angle)])
        send_goals(world, idle, goals, self.goal_radius)


class WanderPlugin(Plugin):
    name = "wander"
    description = "idle creatures get random goals near where they are"
    requires = ("locomotion",)
    config_schema = settings(
        radius=number(0.2, 50, 1.0, "Metres: new goals lie radius / 2 to radius away."),
        **replanning(0.5),
    )

    def problems(self, scene: Mapping[str, object]) -> list[Problem]:
        return farther_than_reach(self, scene, "radius", times=2)

    def systems(self) -> list[System]:
        return [Wander(**plugin_config(self, self.config))]
