"""A level's `game` key against the registered modes, its defaults, the world's result.

    check_game(scene, registries)   # the `SceneChecks` entry: problems of `game`
    rules(scene, mode)              # scene["game"] with the mode's defaults filled in
    playing(world)                  # (mode name, GameResult) of the world's game, or None

Reads the scene's `game` and the `GameModes` registry; writes nothing. A `game.mode`
no plugin on registered is one problem naming the registered modes; the other keys of
`game` are checked against the mode's schema (`mode` added, unknown keys refused unless
the schema allows them), then the mode's `problems` run on the scene with its defaults.
A plugin on that registers another mode is a problem too (one mode a level: its
plugin would build its game from this `game`).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING

from ecs_tentacles.game.modes import GameMode, GameModes, GameResult
from ecs_tentacles.plugin import Problem
from ecs_tentacles.scene.defaults import filled
from ecs_tentacles.scene.validate import schema_problems

if TYPE_CHECKING:
    from ecs_tentacles.host import Host
    from ecs_tentacles.registry import Registries


def mode_schema(mode: GameMode) -> dict[str, object]:
    """The JSON Schema of a `game` key of `mode`: the mode's schema, `mode` added."""
    given, required = mode.schema.get("properties", {}), mode.schema.get("required", [])
    if not isinstance(given, Mapping) or not isinstance(required, list):
        raise TypeError(f"game mode {mode.name!r}: its schema's properties and required")
    properties = {"mode": {"const": mode.name}, **given}
    return {
        "type": "object",
        "additionalProperties": False,
        **mode.schema,
        "properties": properties,
        "required": ["mode", *required],
    }


def unknown(name: str, modes: Mapping[str, GameMode]) -> str:
    """Why `name` is not a mode here, naming the registered ones."""
    if not modes:
        return (
            f"{name!r} is not a registered game mode (no plugin on registers one: turn the"
            ' mode\'s plugin on, as "plugins": {"herding": {}})'
        )
    return f"{name!r} is not a registered game mode (registered: {', '.join(sorted(modes))})"


def check_game(scene: Mapping[str, object], registries: Registries) -> list[Problem]:
    """The problems of a defaults-filled scene's `game` (none without one)."""
    game = scene.get("game")
    if not isinstance(game, Mapping):
        return []
    modes = {mode.name: mode for mode in registries.get(GameModes)}
    name = str(game.get("mode"))
    mode = modes.get(name)
    if mode is None:
        return [(("game", "mode"), unknown(name, modes))]
    others = sorted({key for key, m in registries.get(GameModes).items() if m.name != name})
    if others:  # a mode's plugin builds its game from `game`: one mode a level
        return [
            (("plugins", key), f"plays another game mode than game.mode {name!r}: turn it off")
            for key in others
        ]
    found = schema_problems(game, mode_schema(mode), ("game",))
    if found or mode.problems is None:
        return found
    return mode.problems({**scene, "game": rules(scene, mode)})


def scene_schema(
    schema: Mapping[str, object], scene: Mapping[str, object], registries: Registries
) -> dict[str, object]:
    """The scene schema `schema` with its `game` key that of the scene's mode (for an
    editor checking a level's file: `ecs-tentacles schema LEVEL`); as it is without one."""
    played = scene.get("game")
    name = played.get("mode") if isinstance(played, Mapping) else None
    mode = next((m for m in registries.get(GameModes) if m.name == name), None)
    properties = schema.get("properties", {})
    if mode is None or not isinstance(properties, Mapping) or "game" not in properties:
        return dict(schema)
    game = {"description": f"A {name} level's rules (game mode {name!r})", **mode_schema(mode)}
    return {**schema, "properties": {**properties, "game": game}}


def rules(scene: Mapping[str, object] | None, mode: GameMode) -> dict[str, object]:
    """`scene["game"]` (a copy) with `mode`'s schema defaults filled in."""
    game = (scene or {}).get("game")
    return filled(game if isinstance(game, Mapping) else {}, mode_schema(mode))


def mode_of(world: Host) -> GameMode | None:
    """The registered mode the world's scene plays (None: no game, or none registered)."""
    game = (world.scene or {}).get("game")
    if not isinstance(game, Mapping):
        return None
    return next((m for m in world.registry(GameModes) if m.name == game.get("mode")), None)


def playing(world: Host) -> tuple[str, GameResult] | None:
    """The world's game now, as its mode reports it: (mode name, result); None: no game."""
    mode = mode_of(world)
    return None if mode is None else (mode.name, mode.result(world))
