"""What the scene validator calls: the scene layer's registry (`ecs_tentacles.registry`),
filled in plugins' `build(app)`, and the world-less registries it is called with.

- `SceneChecks`: `entry(scene, registries)` -> problems ((json path, message) pairs) of
  a schema-valid, defaults-filled scene, for rules that depend on what the scene's
  plugins registered (the game layer: `game.mode` names a registered mode, and the
  mode's own keys). `registries` are those the scene's plugins fill, built without a
  world (`plugin_entries`).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import TYPE_CHECKING

from ecs_tentacles.plugin import Problem, calling
from ecs_tentacles.registry import App, Registries, Registry

if TYPE_CHECKING:
    from ecs_tentacles.plugin import Plugin


class SceneChecks(Registry[Callable[[Mapping[str, object], Registries], list[Problem]]]):
    """Checks of a scene against what its plugins registered."""


def plugin_entries(plugins: Sequence[Plugin]) -> Registries:
    """The registries `plugins` fill, built without a world (`App.world` is None); a
    `build` that calls sys.exit is a one-line `HookFailure` naming the plugin."""
    registries = Registries()
    for plugin in plugins:
        with calling(plugin, "build"):
            plugin.build(App(registries, plugin))
    return registries
