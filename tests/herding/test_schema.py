"""The scene's `game` key: bad values are one line naming their path."""

from __future__ import annotations

from typing import Any

import pytest

from ecs_tentacles.scene.errors import SceneError
from ecs_tentacles.world import World
from tests.herding.levels import level


@pytest.mark.parametrize(
    ("change", "says"),
    [
        ({"mode": "chess"}, "game.mode"),
        ({"need": 0}, "game.need"),
        ({"need": 3}, "game.need: 3 is more than the scene's 2 creatures"),
        ({"seconds": 1}, "game.seconds"),
        ({"pen": {"centre": [1, 0]}}, "game.pen"),
        ({"pen": {"centre": [1, 0], "radius": -1}}, "game.pen.radius"),
        ({"predator": {"position": [1.2, 0.1]}}, "game.predator.position: inside the pen"),
        ({"predator": {"speed": "fast"}}, "game.predator.speed"),
        (
            {"pen": {"centre": [1.2, 0], "radius": 0.6, "gate": {"width": 1.5}}},
            "game.pen.gate.width: 1.5 is wider than the pen",
        ),
        ({"bonus": 1}, "game"),
    ],
)
def test_a_bad_game_key_is_one_line_with_its_path(change: dict[str, Any], says: str) -> None:
    with pytest.raises(SceneError) as caught:
        World.from_scene(level(**change))
    lines = str(caught.value).splitlines()
    assert len(lines) == 1 and says in lines[0], lines


def test_the_herding_plugin_needs_a_game_and_a_game_needs_the_plugin() -> None:
    scene = level()
    del scene["game"]
    with pytest.raises(SceneError, match=r"^game: required when the herding plugin is on"):
        World.from_scene(scene)
    scene = level()
    scene["plugins"]["herding"] = False
    with pytest.raises(SceneError, match=r"game: unknown key: the game plugin's, which is off"):
        World.from_scene(scene)


def test_the_levels_schema_for_editors_is_the_assembled_one_and_every_level_is_valid() -> None:
    """`herding_level.schema.json` (what the levels' "$schema" names) is `ecs-tentacles schema
    herding_1_field`'s output, and every bundled level passes it."""
    import importlib.resources
    import json

    import jsonschema

    from ecs_tentacles.game.rules import scene_schema
    from ecs_tentacles.scene.load import bundled_scene, load_scene_plugins
    from ecs_tentacles.scene.registries import plugin_entries
    from ecs_tentacles.scene.schema import schema_for

    folder = importlib.resources.files("ecs_tentacles.assets")
    written = json.loads((folder / "schema" / "herding_level.schema.json").read_text())
    first, plugins = load_scene_plugins(bundled_scene("herding_1_field"))
    assert written == scene_schema(schema_for(plugins), first, plugin_entries(plugins)), (
        "regenerate: ecs-tentacles schema herding_1_field > assets/schema/herding_level.schema.json"
    )
    for name in ("herding_1_field", "herding_2_shore", "herding_3_maze"):
        scene = json.loads(bundled_scene(name).read_text())
        assert scene["$schema"] == "../schema/herding_level.schema.json"
        jsonschema.validate(scene, written)
        World.from_scene(scene).close()  # and it builds
