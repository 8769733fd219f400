"""flock: a crowd moves together (Reynolds' boids), steering through goals.

    "plugins": {"flock": {"toward": [4, 0]}}

Every `interval` seconds the `flock` system (stage decide) steers every creature at
once from its mantle position and velocity (measured over the last interval) and
those of its neighbours (mantles closer than `radius`):
- separation: away from neighbours closer than `separation`, harder the closer;
- alignment: along the neighbours' mean velocity;
- cohesion: toward the neighbours' centre;
- seek (when `toward` is given): toward that point, so the flock travels.
The weighted sum is a direction; the creature's goal is set `step` metres along it.
A creature with nothing to steer by keeps its goal.

Reads: CreatureStore (mantle_row, entity), Transform store (mantle positions).
Writes: goals, through `travel(world).send` (`ecs_tentacles.behaviour`).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

import numpy as np

from ecs_tentacles.behaviour import DestinationSystem
from ecs_tentacles.numeric.vectors import unit_rows
from ecs_tentacles.plugin import Plugin, Problem
from ecs_tentacles.scene.defaults import plugin_config
from ecs_tentacles.system import System
from ecs_tentacles_examples import farther_than_reach, number, replanning, send_goals, settings

if TYPE_CHECKING:
    from ecs_tentacles.host import Host
    from ecs_tentacles.roster_change import RosterChange

CRAWL_SPEED = 0.1  # m/s: a neighbour moving this fast aligns others fully


class Flock(DestinationSystem):
    """Separation, alignment, cohesion (and seek) over all mantles -> one goal each."""

    name = "flock"
    reads = ("transforms.pos", "creatures.entity", "creatures.mantle_row")
    state_attributes = ("last",)  # positions at the last plan: velocities after a restore

    def __init__(self, config: Mapping[str, Any]):
        self.config = dict(config)
        self.weights = np.array([config[k] for k in ("separate", "align", "cohere", "seek")])
        self.every = 1
        self.last: np.ndarray | None = None

    def setup(self, world: Host) -> None:
        self.every = max(1, round(self.config["interval"] * world.settings.fps))

    def roster_changed(self, world: Host, change: RosterChange) -> None:
        if self.last is not None:  # a newcomer starts still
            mantle = world.transforms.pos[world.creatures.mantle_row[-1:], :2]
            self.last = change.follow(self.last, "creatures", mantle)

    def steering(self, pos: np.ndarray, vel: np.ndarray) -> np.ndarray:
        """The four unweighted rules (4, n, 2) from (n, 2) mantle positions and velocities."""
        config = self.config
        offset = pos[:, None, :] - pos[None, :, :]  # i - j
        gap = np.linalg.norm(offset, axis=2)
        np.fill_diagonal(gap, np.inf)
        near = gap < config["radius"]
        count = np.maximum(near.sum(axis=1), 1)[:, None]
        # 0 at `separation`, growing without bound as two mantles meet
        apart = np.maximum(gap, 1e-9)  # two mantles at one point still push
        push = np.where(gap < config["separation"], config["separation"] / apart - 1, 0.0)
        separate = np.einsum("ij,ijk->ik", push / apart, offset)
        align = (near @ vel) / count / CRAWL_SPEED
        align /= np.maximum(np.linalg.norm(align, axis=1, keepdims=True), 1)  # at most 1
        cohere = np.where(near.any(axis=1)[:, None], (near @ pos) / count - pos, 0.0)
        cohere /= config["radius"]
        toward = config.get("toward")
        seek = unit_rows(np.asarray(toward, dtype=float)[None, :2] - pos) if toward else 0 * pos
        return np.stack([separate, align, cohere, seek])

    def process(self, world: Host, dt: float) -> None:
        if world.frame % self.every:
            return
        creatures = world.creatures
        pos = world.transforms.pos[creatures.mantle_row, :2].copy()
        seconds = self.every * dt
        vel = np.zeros_like(pos) if self.last is None else (pos - self.last) / seconds
        self.last = pos
        direction = np.einsum("w,wnk->nk", self.weights, self.steering(pos, vel))
        steer = np.flatnonzero(np.linalg.norm(direction, axis=1) > 1e-6)
        goals = pos[steer] + self.config["step"] * unit_rows(direction[steer])
        send_goals(world, steer, goals, self.config["goal_radius"])


class FlockPlugin(Plugin):
    name = "flock"
    description = "the crowd moves together: separation, alignment, cohesion through goals"
    requires = ("locomotion",)
    config_schema = settings(
        radius=number(0.5, 100, 3.0, "Metres: mantles closer than this are neighbours."),
        separation=number(0.3, 50, 1.4, "Metres: neighbours closer than this push away."),
        separate=number(0, 10, 1.5, "Weight of separation."),
        align=number(0, 10, 0.5, "Weight of alignment (the neighbours' mean velocity)."),
        cohere=number(0, 10, 1.0, "Weight of cohesion (toward the neighbours' centre)."),
        seek=number(0, 10, 1.0, "Weight of seeking `toward`."),
        toward={
            "type": "array",
            "minItems": 2,
            "maxItems": 2,
            "items": {"type": "number", "minimum": -1e4, "maximum": 1e4},
            "description": "Optional [x, y] in metres the flock travels to.",
        },
        step=number(0.4, 20, 0.8, "Metres ahead of a creature its goal is set."),
        **replanning(1.0),
    )

    def problems(self, scene: Mapping[str, Any]) -> list[Problem]:
        return farther_than_reach(self, scene, "step")

    def systems(self) -> list[System]:
        return [Flock(plugin_config(self, self.config))]
