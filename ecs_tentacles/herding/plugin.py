"""`HerdingPlugin`: the herding game as a plugin (`"plugins": {"herding": {}}`).

Game mode "herding" (the scene's `game`, whose keys are `ecs_tentacles.herding.schema`'s;
the `game` layer owns the key); resource `HerdingGame`
(`ecs_tentacles.herding.game`); systems `Predator`, `Herd` and `Referee`
(`herding/systems/`: `Herd` makes the creatures flee the predator and graze as a
flock, so no flee plugin is needed). It needs locomotion and the game layer.

What it adds to the registries in `build`:
- `GameModes` (`ecs_tentacles.game.modes`): the mode "herding", its rules' schema and
  checks, and its result (which ends `run` and `play --headless` once won or lost);
- `StaticGeometry` (`ecs_tentacles.physics.model`): the pen's fence, solid to the
  creatures (`ecs_tentacles.herding.fence`);
- `Dangers` (`ecs_tentacles.behaviour`): the predator, so everything that fears
  dangers fears it (the flee plugin runs, fur's emotion raises quills);
- `Lines`, `Spheres` and `FramedPoints` (the renderer): the pen's ring on the ground,
  the predator and the ring of its reach, kept in view by "frame all";
- `Panels` (the sandbox): the game's HUD section and its banner, which also takes the
  mouse (drag: the predator follows) and the keys R (restart) and P (pause);
- `RunSummaries` (the command line): the game's outcome in `run`'s report;
- `TakeTracks` (takes): the game's events as a points track (`game`), one locator
  per penned creature where it was penned, and one at the pen when the game ends.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.behaviour import Dangers, DangerSource
from ecs_tentacles.game.modes import GameMode, GameModes, GameResult
from ecs_tentacles.herding.game import GameState, HerdingGame
from ecs_tentacles.herding.schema import GAME, game_problems, plugin_problems
from ecs_tentacles.plugin import Plugin, Problem

if TYPE_CHECKING:
    from ecs_tentacles.host import Host
    from ecs_tentacles.registry import App
    from ecs_tentacles.system import System


class HerdingPlugin(Plugin):
    name = "herding"
    description = "the herding game: drive creatures into a pen with a predator"
    requires = ("locomotion", "game")

    def problems(self, scene: Mapping[str, object]) -> list[Problem]:
        return plugin_problems(scene)

    def resources(self, world: Host) -> list[object]:
        scene = world.scene or {}
        name = str(scene.get("name") or "level")
        return [HerdingGame(scene["game"], name, world.settings.fps)]

    def ready(self, world: Host) -> None:
        world.resource(HerdingGame).start = world.snapshot()

    def systems(self) -> list[System]:
        from ecs_tentacles.herding.systems.herd import Herd
        from ecs_tentacles.herding.systems.predator import Predator
        from ecs_tentacles.herding.systems.referee import Referee

        return [Predator(), Herd(), Referee()]

    def snapshot(self, world: Host) -> object:
        return world.resource(HerdingGame).state.copy()

    def restore(self, world: Host, state: object) -> None:
        if not isinstance(state, GameState):
            raise TypeError(f"herding: a snapshot's state is a GameState, not {state!r}")
        world.resource(HerdingGame).state = state.copy()

    def build(self, app: App) -> None:
        from ecs_tentacles.cli.registries import RunSummaries
        from ecs_tentacles.herding import entries, fence
        from ecs_tentacles.physics.model import StaticGeometry
        from ecs_tentacles.render.registries import FramedPoints, Lines, Panels, Spheres
        from ecs_tentacles.take.registries import TakeTracks

        app.add(GameModes, GameMode("herding", GAME, _result, game_problems, self.description))
        if app.world is not None:  # (a shard planner builds plugins without a world)
            app.add(StaticGeometry, fence.static_geometry(app.world))
        app.add(Dangers, DangerSource(sense=_predator_danger))
        app.add(Lines, entries.lines)
        app.add(Spheres, entries.spheres)
        app.add(FramedPoints, entries.framed_points)
        app.add(Panels, entries.panels)
        app.add(RunSummaries, entries.run_summary)
        app.add(TakeTracks, entries.take_tracks)


def _predator_danger(world: Host) -> tuple[np.ndarray, np.ndarray]:
    from ecs_tentacles.ground import ground_of

    xy = world.resource(HerdingGame).predator
    z = ground_of(world).height(xy[None])[0]
    return np.array([[xy[0], xy[1], z]]), np.array([-1])


def _result(world: Host) -> GameResult:
    game = world.resource(HerdingGame)
    details = {"penned": game.penned, "need": game.need, "left": round(game.left, 3)}
    text = f"{game.penned} of {game.need} penned"
    return GameResult(game.outcome, game.elapsed, game.level, details, text)
