"""flee: creatures near a threat get a goal away from it.

    "plugins": {"flee": {"distance": 1.5, "run": 1.0}}

Every `interval` seconds the `flee` system (stage decide) measures, for every creature
at once, the ground distance to every danger (`ecs_tentacles.behaviour.dangers`: the scene's
keyframed threats and creatures marked `"threat": true`, never a creature's own
mantle). A creature with threats closer than `distance` gets a goal `run` metres away
in the direction that leads away from them, each threat weighted by how close it is.
Creatures out of reach keep whatever goal they had.

Reads: `dangers(world)` (positions and owners), CreatureStore (mantle_row, entity),
Transform store (mantle positions). Writes: goals, through `travel(world).send`
(`ecs_tentacles.behaviour`).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.behaviour import DestinationSystem, dangers
from ecs_tentacles.plugin import Plugin, Problem
from ecs_tentacles.scene.defaults import plugin_config
from ecs_tentacles.system import System
from ecs_tentacles_examples import farther_than_reach, number, replanning, send_goals, settings

if TYPE_CHECKING:
    from ecs_tentacles.host import Host


class Flee(DestinationSystem):
    """Creatures within `distance` of a threat head `run` metres away from it."""

    name = "flee"
    calls_hooks = True  # the Dangers entries (`behaviour.dangers`)
    reads = ("transforms.pos", "creatures.entity", "creatures.mantle_row")

    def __init__(self, distance: float, run: float, interval: float, goal_radius: float):
        self.distance = distance
        self.run = run
        self.interval = interval
        self.goal_radius = goal_radius
        self.every = 1

    def setup(self, world: Host) -> None:
        self.every = max(1, round(self.interval * world.settings.fps))

    def process(self, world: Host, dt: float) -> None:
        if world.frame % self.every:
            return
        threats, owners = dangers(world)
        creatures = world.creatures
        if not len(threats) or not creatures.count:
            return
        mantles = world.transforms.pos[creatures.mantle_row, :2]
        away = mantles[:, None, :] - threats[None, :, :2]  # (creatures, threats, 2)
        gap = np.linalg.norm(away, axis=2)
        near = (gap < self.distance) & (owners[None, :] != creatures.entity[:, None])
        # a unit vector away from each threat near, weighted from 1 (on it) to 0 (at distance)
        weight = np.where(near, (1 - gap / self.distance) / np.maximum(gap, 1e-9), 0.0)
        push = np.einsum("ct,ctk->ck", weight, away)
        length = np.linalg.norm(push, axis=1)
        fleeing = np.flatnonzero(length > 1e-9)
        goals = mantles[fleeing] + self.run * push[fleeing] / length[fleeing, None]
        send_goals(world, fleeing, goals, self.goal_radius)


class FleePlugin(Plugin):
    name = "flee"
    description = "creatures near a threat crawl away from it"
    requires = ("locomotion",)  # dangers from any plugin (`behaviour.dangers`), threats or yours
    config_schema = settings(
        distance=number(0.1, 100, 1.5, "Metres: threats closer than this are fled."),
        run=number(0.2, 100, 1.0, "Metres ahead of the creature its flight goal lies."),
        **replanning(1.0),
    )

    def problems(self, scene: Mapping[str, object]) -> list[Problem]:
        return farther_than_reach(self, scene, "run")

    def systems(self) -> list[System]:
        return [Flee(**plugin_config(self, self.config))]
