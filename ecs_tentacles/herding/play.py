"""Playing a herding level without a window: the bot, recorded inputs, replays.

    world = World.from_scene("herding_1_field")
    result = play(world, Bot())                  # the bot plays until the game ends
    again = play(World.from_scene(...), Replay(result["log"], result["runs"]))  # the same game

`play` steps the world, asking the player (a `Bot`, a `Replay`, or anything with
`decide(world, game)`) where to aim the predator every `every` frames (0.25 s), until
the game is won or lost (or `max_seconds` of game time pass). It returns the game's
summary, the input logs (`log`: aims, `runs`: run/walk changes), the wall time and the
median frame's step time (`frame_ms`: physics and every system) with its real-time
factor.

`Bot` is a simple, honest strategy, a sheepdog's, one creature at a time: take the
creature nearest the gate, get behind it (on the side away from where it should go,
`behind` metres off) and push it: toward the point just outside the gate, or, once it
stands in the funnel before the gate (within 40 degrees of its axis), through it; to
get behind it, go around it (out of its reach) and around the pen, never through them.
It runs (Shift) only to get somewhere far with no creature near, and walks to push.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Protocol

import numpy as np

from ecs_tentacles.game.modes import play_out
from ecs_tentacles.herding.fence import Fence
from ecs_tentacles.herding.game import HerdingGame

if TYPE_CHECKING:
    from ecs_tentacles.host import Host
    from ecs_tentacles.world import World


class Player(Protocol):
    def decide(self, world: Host, game: HerdingGame) -> Sequence[float] | None: ...


class Bot:
    """Push the creature nearest the gate to it and in; go around it and the pen."""

    def __init__(self, behind: float = 0.9, approach: float = 1.0):
        self.behind = behind  # metres behind the creature pushed
        self.approach = approach  # metres outside the gate the creatures are brought to
        self.chosen: int | None = None  # the creature pushed, until it is penned

    def decide(self, world: Host, game: HerdingGame) -> Sequence[float] | None:
        creatures = world.creatures
        xy = world.transforms.pos[creatures.mantle_row, :2]
        left = ~np.isin(creatures.entity, game.state.penned)
        if not left.any():
            return None
        fence = Fence.of(game)
        outward = (fence.gate_point - fence.centre) / fence.radius
        mouth = fence.gate_point + self.approach * outward  # just outside the gate
        rows = np.flatnonzero(left)
        entities = creatures.entity[rows]
        if self.chosen not in entities.tolist():  # penned (or gone): the next nearest
            gaps = np.hypot(*(xy[rows] - mouth).T)
            self.chosen = int(entities[int(np.argmin(gaps))])
        pushed = xy[rows[entities.tolist().index(self.chosen)]]
        # in the funnel before the gate (within 40 degrees of its axis): push it through the
        # gate, else to the mouth
        rel = pushed - fence.gate_point
        gap = float(np.hypot(*rel))
        in_funnel = gap < self.approach + 1.5 and float(rel @ outward) > np.cos(0.7) * gap
        goal = fence.gate_point - 0.8 * outward if in_funnel else mouth
        to_goal = goal - pushed
        to_goal = to_goal / max(float(np.hypot(*to_goal)), 1e-9)
        target = self._outside(fence, pushed - self.behind * to_goal, 0.5)
        aim = self._behind(game.predator, pushed, game.reach + 0.1, target, fence)
        aim = self._around(game.predator, fence.centre, fence.radius + 0.3, aim)
        clear = float(np.min(np.hypot(*(xy[rows] - game.predator).T))) > game.run_reach + 0.3
        far = float(np.hypot(*(aim - game.predator))) > 1.5
        game.run(world, clear and far and game.state.stamina > 0.4)
        return (float(aim[0]), float(aim[1]))

    @staticmethod
    def _outside(fence: Fence, point: np.ndarray, margin: float) -> np.ndarray:
        """`point`, or the nearest point `margin` m outside the pen (the predator keeps out)."""
        off = point - fence.centre
        gap = float(np.hypot(*off))
        keep = fence.radius + margin
        return point if gap >= keep else fence.centre + off * (keep / max(gap, 1e-9))

    @staticmethod
    def _behind(
        at: np.ndarray, centre: np.ndarray, keep: float, target: np.ndarray, fence: Fence
    ) -> np.ndarray:
        """`target` (behind the creature at `centre`) when the predator is on its side
        already (within 60 degrees of it, seen from the creature); else a step round the
        creature, `keep` m out, toward that side (so it is not pushed the wrong way), or
        round the other way when the pen is in the way."""
        a, b = at - centre, target - centre
        la, lb = float(np.hypot(*a)), float(np.hypot(*b))
        if la < 1e-9 or lb < 1e-9 or np.dot(a, b) > 0.5 * la * lb:
            return target
        radial = a / la
        side = np.array([-radial[1], radial[0]])
        if np.dot(side, b) < 0:
            side = -side
        steps = [centre + keep * (radial + s) / np.sqrt(2.0) * 1.2 for s in (side, -side)]
        clear = [np.hypot(*(p - fence.centre)) > fence.radius + 0.5 for p in steps]
        step: np.ndarray = steps[0] if clear[0] or not clear[1] else steps[1]
        return step

    @staticmethod
    def _around(at: np.ndarray, centre: np.ndarray, keep: float, target: np.ndarray) -> np.ndarray:
        """`target`, or a point on the circle of radius `keep` about `centre` that leads
        there without crossing the circle (a target inside it is entered from its side)."""
        off = target - centre
        gap = float(np.hypot(*off))
        edge = centre + off * (keep / gap) if 1e-9 < gap < keep else target
        seg = edge - at
        length = float(np.hypot(*seg))
        if length < 1e-9:
            return target
        t = np.clip(np.dot(centre - at, seg) / length**2, 0.0, 1.0)
        if np.hypot(*(at + t * seg - centre)) >= 0.95 * keep:
            return target
        radial = (at - centre) / max(float(np.hypot(*(at - centre))), 1e-9)
        if np.hypot(*(at - centre)) < 0.95 * keep:  # inside the circle: outward is fine
            return target if np.dot(seg, radial) > 0 else centre + 1.3 * keep * radial
        # step around: the tangent direction turning toward the target's side
        side = np.array([-radial[1], radial[0]])
        if np.dot(side, target - centre) < 0:
            side = -side
        step: np.ndarray = centre + keep * (radial + side) / np.sqrt(2.0) * 1.2
        return step


class Replay:
    """Aims where a recorded log aimed, and runs when it ran, at the same frames."""

    def __init__(
        self,
        log: Sequence[tuple[int, float, float]],
        runs: Sequence[tuple[int, bool]] = (),
    ):
        self.log = sorted(log)
        self.next = 0
        self.runs = sorted(runs)
        self.next_run = 0

    def running(self, frame: int) -> list[bool]:
        """The run/walk changes due by `frame`, in order."""
        out = []
        while self.next_run < len(self.runs) and self.runs[self.next_run][0] <= frame:
            out.append(bool(self.runs[self.next_run][1]))
            self.next_run += 1
        return out

    def frames_to_next(self, frame: int, most: int) -> int:
        """Frames to step before the next logged aim is due (at most `most`)."""
        due = [most]
        if self.next < len(self.log):
            due.append(self.log[self.next][0] - frame)
        if self.next_run < len(self.runs):
            due.append(self.runs[self.next_run][0] - frame)
        return max(1, min(due))

    def due(self, frame: int) -> list[tuple[float, float]]:
        out = []
        while self.next < len(self.log) and self.log[self.next][0] <= frame:
            out.append((self.log[self.next][1], self.log[self.next][2]))
            self.next += 1
        return out


def play(
    world: World,
    player: Bot | Replay | Player,
    *,
    every: float = 0.25,
    max_seconds: float | None = None,
) -> dict[str, object]:
    """Play the world's level to its end; the game's summary, `log`, `wall_s`."""
    game = world.resource(HerdingGame)

    def turn(block: int) -> int:
        if isinstance(player, Replay):
            for point in player.due(world.frame):
                game.aim(world, point)
            for running in player.running(world.frame):
                game.run(world, running)
            return player.frames_to_next(world.frame, block)
        aim = player.decide(world, game)
        if aim is not None:
            game.aim(world, aim)
        return block

    limit = game.seconds if max_seconds is None else max_seconds
    # a frame's step (physics and every system), by block
    wall_s, frame_ms = play_out(world, game, limit, every, turn)
    median = float(np.median(frame_ms)) if frame_ms else 0.0
    return {
        **game.summary(),
        "log": list(game.state.log),
        "runs": list(game.state.runs),
        "wall_s": wall_s,
        "frame_ms": round(median, 2),  # median over the game's blocks
        "realtime_factor": round(1000.0 * world.settings.dt / median, 2) if median else None,
    }
