"""`RacePlugin`: race to the flag as a plugin (`"plugins": {"race": {}}`), game mode "race".

Keys of the scene's `game` (`ecs_tentacles.race.rules`); resource `RaceGame`
(`ecs_tentacles.race.game`); systems `Steering` and `Referee` (`race/systems/`). It
needs the locomotion plugin (what sends creatures: `behaviour.travel`) and the game
layer (turned on with it).

What it adds to the registries in `build`:
- `GameModes` (`ecs_tentacles.game.modes`): the mode "race": its keys, their checks,
  its result (which ends `run` and `play --headless` once the race is won or lost);
- `Lines`, `Spheres`, `FramedPoints` (the renderer): the flag, its ring, the runner's
  ring and path;
- `Panels` (the sandbox): the Race section and its banner, which also takes the mouse
  (click: the runner goes there; shift-click: and then there) and the keys R and P.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING

from ecs_tentacles.game.modes import GameMode, GameModes
from ecs_tentacles.game.rules import rules
from ecs_tentacles.plugin import Plugin, Problem
from ecs_tentacles.race import rules as race_rules
from ecs_tentacles.race.game import RaceGame, RaceState

if TYPE_CHECKING:
    from ecs_tentacles.host import Host
    from ecs_tentacles.registry import App
    from ecs_tentacles.system import System

MODE_NAME = "race"


class RacePlugin(Plugin):
    name = "race"
    description = "race to the flag: steer your creature there before the rivals"
    requires = ("locomotion", "game")

    def mode(self) -> GameMode:
        """The mode this plugin registers."""
        from ecs_tentacles.race.entries import result

        return GameMode(MODE_NAME, race_rules.RULES, result, race_rules.problems, self.description)

    def problems(self, scene: Mapping[str, object]) -> list[Problem]:
        if scene.get("game") is None:
            return [(("game",), "required when the race plugin is on (the level's rules)")]
        return []

    def resources(self, world: Host) -> list[object]:
        scene = world.scene or {}
        name = str(scene.get("name") or "level")
        return [RaceGame(rules(scene, self.mode()), name, world.settings.fps)]

    def build_scene(self, world: Host, scene: Mapping[str, object]) -> None:
        race = world.resource(RaceGame)
        race.runner = world.creature(race.runner_name)

    def ready(self, world: Host) -> None:
        world.resource(RaceGame).start = world.snapshot()

    def systems(self) -> list[System]:
        from ecs_tentacles.race.systems.referee import Referee
        from ecs_tentacles.race.systems.steering import Steering

        return [Steering(), Referee()]

    def snapshot(self, world: Host) -> object:
        return world.resource(RaceGame).state.copy()

    def restore(self, world: Host, state: object) -> None:
        if not isinstance(state, RaceState):
            raise TypeError(f"race: a snapshot's state is a RaceState, not {state!r}")
        world.resource(RaceGame).state = state.copy()

    def build(self, app: App) -> None:
        from ecs_tentacles.race import entries
        from ecs_tentacles.render.registries import FramedPoints, Lines, Panels, Spheres

        app.add(GameModes, self.mode())
        app.add(Lines, entries.lines)
        app.add(Spheres, entries.spheres)
        app.add(FramedPoints, entries.framed_points)
        app.add(Panels, entries.panels)
