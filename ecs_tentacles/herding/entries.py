"""The herding game's entries in the renderer's, sandbox's, take's and report's registries.

- `lines`: the pen's ring on the ground (green; gold once won, red once lost), its
  fence (posts and two rails, none across the gate) and the ring of the predator's
  reach (orange walking, yellow running, drawn thick);
- `spheres`: the predator's body (`ecs_tentacles.herding.predator_body`: body, head
  and ears, facing where it goes) and the gate's posts;
- `framed_points`: the pen and the predator, which "frame all" keeps in view;
- `panels`: the HUD's Game section and the win/lose banner (`ecs_tentacles.herding.hud`);
- `run_summary`: `run`'s report gets the outcome (`game won in 41.2 s, 5 of 4 penned`);
- `take_tracks`: a points track `game`: one locator per penned creature, where and from
  the frame it was penned.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.cli.registries import RunSummary
from ecs_tentacles.ground import ground_of
from ecs_tentacles.herding.fence import Fence
from ecs_tentacles.herding.game import LOST, PLAYING, WON, HerdingGame
from ecs_tentacles.herding.predator_body import predator_body
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
REACH_RGBA = (1.0, 0.45, 0.1, 1.0)  # orange: the walking predator's reach
RUN_RGBA = (1.0, 0.9, 0.15, 1.0)  # yellow: the running predator's
FENCE_RGBA = (0.55, 0.38, 0.2, 1.0)  # wood
GATE_RGBA = (1.0, 0.85, 0.3, 1.0)
RAILS = (0.4, 0.85)  # the rails' heights, in parts of the fence's height
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


def fence_lines(world: Host, fence: Fence) -> np.ndarray:
    """Line-list vertices of the fence: a post at each panel's ends and two rails."""
    centres, half, angles = fence.boxes()
    along = half[:, None] * np.stack([np.cos(angles), np.sin(angles)], axis=1)
    ends = np.concatenate([centres - along, centres + along])  # (2m, 2)
    base = ground_of(world).height(ends)
    tops = [base + fence.height * part for part in RAILS]
    m = len(centres)
    rails = [
        np.stack([np.column_stack([ends[:m], top[:m]]), np.column_stack([ends[m:], top[m:]])], 1)
        for top in tops
    ]
    posts = np.stack([np.column_stack([ends, base]), np.column_stack([ends, tops[-1] + 0.05])], 1)
    points = np.concatenate([*rails, posts]).reshape(-1, 3)
    return np.column_stack([points, np.tile(FENCE_RGBA, (len(points), 1))])


def lines(world: Host, view: RenderView) -> list[np.ndarray]:
    game = world.resource(HerdingGame)
    pen = ring(world, game.pen_centre, game.pen_radius, PEN_RGBA[game.outcome])
    reach = game.scare
    colour = RUN_RGBA if game.sprinting else REACH_RGBA
    rings = [ring(world, game.predator, reach + d, colour) for d in (-0.04, 0.0, 0.04)]
    return [pen, fence_lines(world, Fence.of(game)), *rings]


def framed_points(world: Host) -> np.ndarray:
    """What "frame all" keeps in view besides the creatures: the pen and the predator."""
    game = world.resource(HerdingGame)
    pen = ring(world, game.pen_centre, game.pen_radius, PEN_RGBA[PLAYING])[0::8, :3]
    predator = np.append(game.predator, ground_of(world).height(game.predator[None])[0])
    return np.vstack([pen, predator[None]])


def spheres(world: Host) -> list[Marker]:
    game = world.resource(HerdingGame)
    fence = Fence.of(game)
    half = fence.half_gate
    angles = fence.heading + np.array([-half, half])
    xy = fence.centre + fence.radius * np.stack([np.cos(angles), np.sin(angles)], axis=1)
    z = ground_of(world).height(xy) + fence.height + 0.06
    posts = Marker(np.column_stack([xy, z]), (0.09, 0.09, 0.09), GATE_RGBA)
    return [*predator_body(world, game), posts]


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


def take_tracks(world: Host) -> list[TrackSource]:
    return [TrackSource(GAME_TRACK, _penned_points)]
