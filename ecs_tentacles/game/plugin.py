"""`GamePlugin`: the game layer's plugin, owner of the scene's `game` key.

Scene key `game` (`game.schema.json`: an object whose `mode` names a game mode). It is
turned on by the plugins that register modes (they list it in `requires`); alone it
adds no system. In `build` it adds a `SceneChecks` entry (`ecs_tentacles.scene.registries`):
`game.mode` must name a mode a plugin on registered, and the rest of `game` is checked
against that mode (`ecs_tentacles.game.rules.check_game`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ecs_tentacles.plugin import Plugin
from ecs_tentacles.scene.schema import fragment

if TYPE_CHECKING:
    from ecs_tentacles.registry import App

GAME = fragment("ecs_tentacles.game", "game")["scene"]["game"]


class GamePlugin(Plugin):
    name = "game"
    description = "game modes: the scene's `game` key names a registered mode"
    scene_schema = {"game": GAME}

    def build(self, app: App) -> None:
        from ecs_tentacles.game.rules import check_game
        from ecs_tentacles.scene.registries import SceneChecks

        app.add(SceneChecks, check_game)
