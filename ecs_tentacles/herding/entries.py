"""The herding game's entries in the renderer's, sandbox's, take's and report's registries.

- `lines`: the pen's ring on the ground (green; gold once won, red once lost) and the
  ring of the predator's reach;
- `spheres`: the predator, a dark sphere above the ground;
- `framed_points`: the pen and the predator, which "frame all" keeps in view;
- `panels`: the HUD's Game section and the win/lose banner (`ecs_tentacles.herding.hud`);
- `run_summary`: `run`'s report gets the outcome (`game won in 41.2 s, 5 of 4 penned`);
- `take_tracks`: a points track `game`: one locator per penned creature, where and from
  the frame it was penned.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from ecs_tentacles.cli.registries import RunSummary
from ecs_tentacles.ground import ground_of
from ecs_tentacles.herding.game import LOST, PLAYING, WON, HerdingGame
from ecs_tentacles.render.registries import Marker
from ecs_tentacles.take.registries import PointsFrame, TrackSource
from ecs_tentacles.take.tracks import TakeTrack

if TYPE_CHECKING:
    from ecs_tentacles.host import Host
    from ecs_tentacles.render.registries import Panel, RenderView, SandboxView

SEGMENTS = 64
LIFT = 0.01  # metres the rings float over the ground
PEN_RGBA = {
    PLAYING: (0.25, 0.85, 0.35, 1.0),  # green
    WON: (1.0, 0.8, 0.2, 1.0),  # gold
    LOST: (0.9, 0.2, 0.2, 1.0),  # red
}
REACH_RGBA = (0.55, 0.1, 0.1, 1.0)
PREDATOR_SIZE = (0.13, 0.13, 0.13)
PREDATOR_RGBA = (0.25, 0.05, 0.05, 1.0)
GAME_TRACK = TakeTrack("game", "points", ("game_pos", "game_live"), "game", "penned")


def ring(world: Host, centre: np.ndarray, radius: float, rgba: tuple[float, ...]) -> np.ndarray:
    """Line-list vertices (2 * SEGMENTS, 7) of a circle draped on the ground."""
    angles = np.linspace(0.0, 2 * np.pi, SEGMENTS + 1)
    xy = centre[None, :2] + radius * np.stack([np.cos(angles), np.sin(angles)], axis=1)
    z = ground_of(world).height(xy) + LIFT
    points = np.column_stack([xy, z])
    out = np.empty((2 * SEGMENTS, 7))
    out[0::2, :3], out[1::2, :3] = points[:-1], points[1:]
    out[:, 3:] = rgba
    return out


def lines(world: Host, view: RenderView) -> list[np.ndarray]:
    game = world.resource(HerdingGame)
    pen = ring(world, game.pen_centre, game.pen_radius, PEN_RGBA[game.outcome])
    return [pen, ring(world, game.predator, game.reach, REACH_RGBA)]


def framed_points(world: Host) -> np.ndarray:
    """What "frame all" keeps in view besides the creatures: the pen and the predator."""
    game = world.resource(HerdingGame)
    pen = ring(world, game.pen_centre, game.pen_radius, PEN_RGBA[PLAYING])[0::8, :3]
    predator = np.append(game.predator, ground_of(world).height(game.predator[None])[0])
    return np.vstack([pen, predator[None]])


def spheres(world: Host) -> list[Marker]:
    game = world.resource(HerdingGame)
    xy = game.predator
    z = ground_of(world).height(xy[None])[0] + PREDATOR_SIZE[2]
    return [Marker(np.array([[xy[0], xy[1], z]]), PREDATOR_SIZE, PREDATOR_RGBA)]


def panels(sandbox: SandboxView) -> list[Panel]:
    from ecs_tentacles.herding.hud import GamePanel

    return [GamePanel(sandbox)]


def run_summary(world: Host) -> RunSummary:
    game = world.resource(HerdingGame)
    counts = {
        "game_penned": game.penned,
        "game_need": game.need,
        "game_won": int(game.outcome == WON),
    }
    if game.outcome == WON:
        text = f"game won in {game.elapsed:.1f} s, {game.penned} of {game.need} penned"
    elif game.outcome == LOST:
        text = f"game lost: {game.penned} of {game.need} penned in {game.seconds:.0f} s"
    else:
        text = f"game on: {game.penned} of {game.need} penned, {game.left:.1f} s left"
    return RunSummary(counts, text)


def _penned_points(world: Host) -> PointsFrame:
    state = world.resource(HerdingGame).state
    n = len(state.penned)
    return PointsFrame(
        keys=list(state.penned),
        creatures=list(state.penned),
        order=[0] * n,
        positions=np.asarray(state.penned_at, dtype=np.float64).reshape(n, 3),
        radii=[0.05] * n,
    )


def take_tracks(world: Host) -> list[Any]:
    return [TrackSource(GAME_TRACK, _penned_points)]
