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
    with pytest.raises(SceneError, match=r"game: unknown key: the herding plugin's, which is off"):
        World.from_scene(scene)
