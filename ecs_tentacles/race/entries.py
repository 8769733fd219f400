"""The race mode's entries in the renderer's, sandbox's and game layer's registries.

- `lines`: the flag's ring on the ground (white while racing; gold once won, red once
  lost), a gold ring round the runner, and the runner's path from its mantle through
  the points still to reach;
- `spheres`: the flag, a pole of small white spheres with a red ball on top;
- `framed_points`: the flag and the runner, which "frame all" keeps in view;
- `panels`: the HUD's Race section and banner (`ecs_tentacles.race.hud`);
- `result`: the race as the game layer reports it (`GameResult`: ends `run`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.game.modes import LOST, PLAYING, WON, GameResult
from ecs_tentacles.ground import ground_of
from ecs_tentacles.race.game import RaceGame
from ecs_tentacles.render.registries import Marker
from ecs_tentacles.render.rings import CIRCLE, draped, line_segments

if TYPE_CHECKING:
    from ecs_tentacles.host import Host
    from ecs_tentacles.render.registries import Panel, RenderView, SandboxView

LIFT = 0.01  # metres the rings float over the ground
FLAG_RGBA = {
    PLAYING: np.array([0.95, 0.95, 0.95, 1.0]),  # white
    WON: np.array([1.0, 0.8, 0.2, 1.0]),  # gold
    LOST: np.array([0.9, 0.2, 0.2, 1.0]),  # red
}
RUNNER_RGBA = np.array([1.0, 0.8, 0.2, 1.0])  # gold: yours
POLE = 0.8  # metres the flag's pole stands
POLE_SIZE = (0.03, 0.03, 0.03)
BALL_SIZE = (0.12, 0.12, 0.12)


def _runner_xy(world: Host, race: RaceGame) -> np.ndarray | None:
    creatures = world.creatures
    row = np.flatnonzero(creatures.entity == race.runner)
    if not len(row):
        return None
    return np.asarray(world.transforms.pos[creatures.mantle_row[row[0]], :2])


def _ring(world: Host, centre: np.ndarray, radius: float, rgba: np.ndarray) -> np.ndarray:
    points = CIRCLE * radius + [centre[0], centre[1], 0.0]
    return line_segments(draped(points, ground_of(world), LIFT), rgba)


def lines(world: Host, view: RenderView) -> list[np.ndarray]:
    race = world.resource(RaceGame)
    out = [_ring(world, race.flag, race.radius, FLAG_RGBA[race.outcome])]
    runner = _runner_xy(world, race)
    if runner is not None:
        out.append(_ring(world, runner, 0.3, RUNNER_RGBA))
        if race.state.path and race.outcome == PLAYING:
            xy = np.vstack([runner[None], np.asarray(race.state.path)])
            points = draped(np.column_stack([xy, np.zeros(len(xy))]), ground_of(world), LIFT)
            out.append(line_segments(points, RUNNER_RGBA))
    return out


def _flag_foot(world: Host, race: RaceGame) -> np.ndarray:
    z = float(ground_of(world).surface(race.flag[None])[0])
    return np.array([race.flag[0], race.flag[1], z])


def spheres(world: Host) -> list[Marker]:
    race = world.resource(RaceGame)
    foot = _flag_foot(world, race)
    heights = np.linspace(0.0, POLE, 12)
    pole = foot + np.column_stack([np.zeros((len(heights), 2)), heights])
    ball = (foot + [0.0, 0.0, POLE + BALL_SIZE[2]])[None]
    red = (0.85, 0.1, 0.1, 1.0)
    return [Marker(pole, POLE_SIZE, (0.95, 0.95, 0.95, 1.0)), Marker(ball, BALL_SIZE, red)]


def framed_points(world: Host) -> np.ndarray:
    """What "frame all" keeps in view besides the creatures: the flag and its top."""
    race = world.resource(RaceGame)
    foot = _flag_foot(world, race)
    return np.vstack([foot, foot + [0.0, 0.0, POLE]])


def panels(sandbox: SandboxView) -> list[Panel]:
    from ecs_tentacles.race.hud import RacePanel

    return [RacePanel(sandbox)]


def result(world: Host) -> GameResult:
    race = world.resource(RaceGame)
    winner = race.winner_name(world)
    details: dict[str, int | float | str] = {
        "runner": race.runner_name,
        "winner": winner,
        "left": round(race.left, 3),
    }
    if race.outcome == WON:
        text = f"{race.runner_name} took the flag"
    elif race.outcome == LOST:
        text = f"{winner} took the flag" if winner else "the time ran out"
    else:
        text = "racing"
    return GameResult(race.outcome, race.elapsed, race.level, details, text)
