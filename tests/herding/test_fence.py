"""The pen's fence: solid to the creatures, crossed only through the gate; a penned
creature stays penned while the predator keeps away."""

from __future__ import annotations

import numpy as np

from ecs_tentacles.behaviour import travel
from ecs_tentacles.herding.fence import THICKNESS, Fence
from ecs_tentacles.herding.game import HerdingGame
from ecs_tentacles.world import World
from tests.herding.levels import level

FENCE = Fence(np.array([0.0, 0.0]), 2.0, np.pi, 1.2, 0.5)  # the gate faces -x


def test_a_way_through_the_fence_is_refused_and_one_through_the_gate_allowed() -> None:
    starts = np.array([[3.0, 0.0], [-3.0, 0.0], [-3.0, 1.9], [0.0, 3.0], [0.5, 0.0]])
    goals = np.array([[0.0, 0.0], [0.0, 0.0], [0.0, 0.0], [0.0, -3.0], [-0.5, 0.3]])
    # east: through the fence; west: through the gate; north-west: past the gate's post;
    # north to south: across the pen (twice through the fence); inside: inside
    assert FENCE.crossing_ok(starts, goals).tolist() == [False, True, False, False, True]


def test_a_goal_against_the_fence_is_refused() -> None:
    starts = np.array([[0.0, 0.0], [3.0, 0.0]])
    goals = np.array([[1.9, 0.0], [2.1, 0.0]])
    assert FENCE.crossing_ok(starts, goals).tolist() == [False, False]


def test_the_fence_runs_round_the_pen_but_the_gate() -> None:
    centres, half, _ = FENCE.boxes()
    angles = np.arctan2(centres[:, 1], centres[:, 0])
    assert not FENCE.in_gate(angles).any()
    covered = 2 * (half - 0.5 * THICKNESS).sum()  # the panels: the circle less the gate
    assert abs(covered - (2 * np.pi * 2.0 - 1.2)) < 0.1


def _pen_at(x: float) -> dict:
    """The test level with a fenced pen east of creature `a`, its gate facing east (away)."""
    scene = level(
        need=2,
        seconds=60,
        pen={"centre": [x, 0.0], "radius": 0.6, "gate": {"heading_deg": 0, "width": 0.5}},
    )
    scene["creatures"] = scene["creatures"][:1]
    scene["game"]["need"] = 1
    return scene


def test_a_creature_driven_at_the_fence_stays_outside() -> None:
    """The predator pushes creature `a` east, straight at the fence's back, for 12 s."""
    with World.from_scene(_pen_at(1.2)) as world:
        game = world.resource(HerdingGame)
        row = world.creatures.mantle_row[0]
        for _ in range(48):
            x, y = world.transforms.pos[row, :2]
            game.aim(world, (float(x) - 0.6, float(y)))
            world.step(15)
        xy = world.transforms.pos[row, :2]
        assert not game.in_pen(xy[None])[0], xy
        assert game.penned == 0 and game.outcome == "playing"
        assert xy[0] > 0.15  # it was driven toward the fence


def test_a_creature_sent_straight_at_the_fence_does_not_pass() -> None:
    """Creature `a` is sent to the pen's centre, through the fence's back, for 20 s (the
    herd's own goals off): the fence, not the goals, stops it."""
    with World.from_scene(_pen_at(1.0)) as world:
        game = world.resource(HerdingGame)
        game.herd["graze_share"] = 0.0
        game.aim(world, (-6.0, 4.0))
        row = world.creatures.mantle_row[0]
        inside = []
        for _ in range(20):
            travel(world).send(world, world.creature("a"), (1.0, 0.0), 0.1)
            world.step(60)
            inside.append(bool(game.in_pen(world.transforms.pos[row, None, :2])[0]))
        assert not any(inside)
        assert world.transforms.pos[row, 0] > 0.1  # it went, and was stopped at the fence


def test_a_penned_creature_stays_in_the_pen_with_no_predator_near() -> None:
    """Creature `a` starts inside the pen; the predator stays 4 m off for 20 s."""
    with World.from_scene(_pen_at(0.0)) as world:
        game = world.resource(HerdingGame)
        row = world.creatures.mantle_row[0]
        game.aim(world, (-4.0, 3.0))
        world.step(2)
        assert game.penned == 1 and game.outcome == "won"
        game.state.outcome = "playing"  # go on playing: does it stay in?
        game.need = 2
        inside = []
        for _ in range(40):
            world.step(30)
            inside.append(bool(game.in_pen(world.transforms.pos[row, None, :2])[0]))
        assert all(inside), inside
        assert game.penned == 1
