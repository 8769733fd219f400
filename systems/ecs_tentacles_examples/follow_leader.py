"""follow_leader: a creature marked `"follow": "<leader>"` crawls after its leader.

    "plugins": {"follow_leader": {"gap": 0.8}},
    "creatures": [{"name": "boss", ...}, {"name": "pup", "follow": "boss", ...}]

Every `interval` seconds the `follow_leader` system (stage decide) looks at every
follower at once: one farther than `gap` + `goal_radius` from its leader gets a goal on
the line to the leader, `gap` metres short of it (so it never crawls into it); one that
is close enough stops (its goals are cleared). Chains (a follows b follows c) work.
The scene check refuses a leader that is not a creature of the scene, or the creature
itself.

Reads: CreatureStore (mantle_row, entity), Transform store (mantle positions), the
scene's `follow` keys (once, at setup). Writes: goals, through `travel(world).send` and
`.stop` (`ecs_tentacles.behaviour`).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

import numpy as np

from ecs_tentacles.behaviour import DestinationSystem, travel
from ecs_tentacles.components import Creature
from ecs_tentacles.plugin import Plugin, Problem
from ecs_tentacles.scene.defaults import plugin_config
from ecs_tentacles.system import System
from ecs_tentacles_examples import number, replanning, settings

if TYPE_CHECKING:
    from ecs_tentacles.host import Host
    from ecs_tentacles.roster_change import RosterChange

KEY = "follow"  # the creature-level scene key


class FollowLeader(DestinationSystem):
    """Followers head for a point `gap` metres short of their leader's mantle."""

    name = "follow_leader"
    reads = (
        "transforms.pos",
        "locomotion.creatures.has_goal",
        "creatures.entity",
        "creatures.mantle_row",
    )

    def __init__(self, gap: float, interval: float, goal_radius: float):
        self.gap = gap
        self.interval = interval
        self.goal_radius = goal_radius
        self.every = 1
        self.followers = np.zeros(0, dtype=np.int64)  # creature rows
        self.leaders = np.zeros(0, dtype=np.int64)  # their leaders' rows

    def setup(self, world: Host) -> None:
        self.every = max(1, round(self.interval * world.settings.fps))
        rows = {c.name: c.row for _, c in world.query(Creature)}  # a shard may lack some
        entries: list[Mapping[str, object]] = list(world.creature_specs.values())  # our key too
        pairs = [
            (rows[entry["name"]], rows[entry[KEY]])
            for entry in entries
            if KEY in entry and entry["name"] in rows and entry[KEY] in rows
        ]
        self.followers, self.leaders = np.array(pairs, dtype=np.int64).reshape(-1, 2).T

    def roster_changed(self, world: Host, change: RosterChange) -> None:
        self.setup(world)  # the pairs by creature row

    def process(self, world: Host, dt: float) -> None:
        if world.frame % self.every or not len(self.followers):
            return
        creatures = world.creatures
        mantles = world.transforms.pos[creatures.mantle_row, :2]
        ahead = mantles[self.leaders] - mantles[self.followers]
        gap = np.linalg.norm(ahead, axis=1)
        behind = gap > self.gap + self.goal_radius
        goals = mantles[self.leaders] - self.gap * ahead / np.maximum(gap, 1e-9)[:, None]
        way = travel(world)
        going = way.going(world)
        for row, goal, far in zip(self.followers, goals, behind, strict=True):
            entity = int(creatures.entity[row])
            if far:
                way.send(world, entity, goal, self.goal_radius)
            elif going[row]:
                way.stop(world, entity)


class FollowLeaderPlugin(Plugin):
    name = "follow_leader"
    description = 'creatures marked "follow": "<name>" crawl after that creature'
    requires = ("locomotion",)
    creature_schema = {
        KEY: {
            "$ref": "#/$defs/name",
            "description": "The name of the creature this one follows (plugin follow_leader).",
        }
    }
    config_schema = settings(
        gap=number(0.3, 50, 0.8, "Metres kept between a follower's and its leader's mantles."),
        **replanning(1.0),
    )

    def problems(self, scene: Mapping[str, Any]) -> list[Problem]:
        creatures = scene.get("creatures", [])
        names = {creature["name"] for creature in creatures}
        problems: list[Problem] = []
        for i, creature in enumerate(creatures):
            leader = creature.get(KEY)
            if leader is None:
                continue
            if leader == creature["name"]:
                problems.append((("creatures", i, KEY), "a creature cannot follow itself"))
            elif leader not in names:
                known = ", ".join(sorted(names))
                problems.append(
                    (("creatures", i, KEY), f'no creature named "{leader}" (there are: {known})')
                )
        return problems

    def systems(self) -> list[System]:
        return [FollowLeader(**plugin_config(self, self.config))]
