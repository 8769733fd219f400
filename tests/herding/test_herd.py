"""The herd: idle creatures graze and keep together; flight goals stay on open ground."""

from __future__ import annotations

import copy
import json

import numpy as np

from ecs_tentacles.herding.fence import Fence
from ecs_tentacles.herding.game import HerdingGame
from ecs_tentacles.herding.open_ground import ALONG, open_goals, open_ground
from ecs_tentacles.scene.load import bundled_scene
from ecs_tentacles.world import World
from tests.herding.levels import CREATURE, level


def _flock() -> dict:
    """Four small creatures in a loose square 2 m across, the predator 6 m off."""
    scene = level(need=1, seconds=60, predator={"position": [-6.0, 6.0]})
    scene["game"]["pen"] = {"centre": [5.0, -5.0], "radius": 0.6}
    scene["creatures"] = [
        {"name": f"c{i}", "position": list(xy), **copy.deepcopy(CREATURE)}
        for i, xy in enumerate([(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)])
    ]
    return scene


def test_idle_creatures_graze_and_stay_together() -> None:
    with World.from_scene(_flock()) as world:
        rows = world.creatures.mantle_row
        start = world.transforms.pos[rows, :2].copy()
        world.step(12 * 60)
        end = world.transforms.pos[rows, :2]
    moved = np.hypot(*(end - start).T)
    assert (moved > 0.1).all(), moved  # none frozen
    spread = np.hypot(*(end - end.mean(axis=0)).T).max()
    assert spread < np.hypot(1.0, 1.0) + 0.3, end  # they did not scatter


def _maze() -> dict:
    """The maze level's walls with one small creature in its bottom corridor."""
    maze = json.loads(bundled_scene("herding_3_maze").read_text())
    scene = level(need=1, seconds=60)
    scene["terrain"] = maze["terrain"]
    scene["game"]["pen"] = maze["game"]["pen"]
    scene["game"]["predator"] = {"position": [-4.6, -2.8]}
    scene["creatures"] = scene["creatures"][:1]
    scene["creatures"][0]["position"] = [0.0, -2.8]
    return scene


def test_flight_goals_in_the_maze_are_on_open_ground() -> None:
    """Creatures by the walls, fleeing straight at them: every goal is off the walls."""
    with World.from_scene(_maze()) as world:
        fence = Fence.of(world.resource(HerdingGame))
        angles = np.radians(np.arange(0, 360, 15))
        starts = np.array([[-3.0, -1.6], [0.0, -4.1], [-5.0, 0.0], [-1.0, 0.8], [4.9, -3.0]])
        starts = np.repeat(starts, len(angles), axis=0)
        wish = np.tile(np.stack([np.cos(angles), np.sin(angles)], axis=1), (5, 1))
        goals, found = open_goals(world, fence, starts, wish, 1.0, np.ones(len(starts), bool))
        assert found.all()
        assert open_ground(world, goals).all()
        clear = np.all([open_ground(world, starts + t * wish) for t in ALONG], axis=0)
        assert not clear.all()  # some wishes were into (or through) the walls, and were turned
        assert not np.allclose(goals[~clear], (starts + wish)[~clear])
        assert np.allclose(goals[clear], (starts + wish)[clear])  # the others kept


def test_a_creature_chased_at_a_maze_wall_is_sent_along_it() -> None:
    """The predator drives the creature south at the outer wall for 6 s: every goal it
    is given is on open ground, and it goes along the wall, not into it."""
    with World.from_scene(_maze()) as world:
        game = world.resource(HerdingGame)
        row = world.creatures.mantle_row[0]
        store = world.stores["locomotion.creatures"]
        goals, places = [], []
        for _ in range(24):
            x, y = world.transforms.pos[row, :2]
            game.aim(world, (float(x), float(y) + 0.6))
            world.step(15)
            if store.has_goal[0]:
                goals.append(np.array(store.goal[0, :2]))
            places.append(world.transforms.pos[row, :2].copy())
        assert goals and open_ground(world, np.array(goals)).all()
        assert (np.array(places)[:, 1] > -4.4 + 0.1).all()  # never in the wall
