"""The race mode registers as a game mode, and a level's `game` is checked against it:
one line naming the field for each problem, and the registered modes for a bad mode."""

from __future__ import annotations

import pytest

from ecs_tentacles.game.modes import GameModes
from ecs_tentacles.scene.errors import SceneError
from ecs_tentacles.scene.load import bundled_scene, load_scene
from ecs_tentacles.world import World
from tests.race.levels import level


def test_the_race_plugin_registers_the_mode_race_and_brings_the_game_layer() -> None:
    with World.from_scene(level()) as world:
        assert [mode.name for mode in world.registry(GameModes)] == ["race"]
        assert [key for key, _ in world.registry(GameModes).items()] == ["race"]
        assert {"game", "race"} <= {plugin.key for plugin in world.plugins}


def test_herding_registers_itself_as_the_mode_herding() -> None:
    with World.from_scene(bundled_scene("herding_1_field")) as world:
        assert [mode.name for mode in world.registry(GameModes)] == ["herding"]


def one_line(scene: dict) -> str:
    with pytest.raises(SceneError) as caught:
        load_scene(scene)
    lines = str(caught.value).splitlines()
    assert len(lines) == 1, lines
    return lines[0]


def test_a_mode_no_plugin_registers_is_one_line_naming_the_field_and_the_modes() -> None:
    assert one_line(level(mode="racing")) == (
        "game.mode: 'racing' is not a registered game mode (registered: race)"
    )
    herding_on = level(mode="racing")
    herding_on["plugins"] = {"flee": {}, "herding": {}}
    assert one_line(herding_on) == (
        "game.mode: 'racing' is not a registered game mode (registered: herding)"
    )


def test_the_mode_s_keys_are_checked_against_its_schema_and_its_rules() -> None:
    assert one_line(level(seconds=1)) == "game.seconds: must be in [5, 3600], got 1"
    assert one_line(level(pen=1)).startswith("game.pen: unknown key (allowed: flag, level, mode,")
    assert (
        one_line(level(runner="nobody")) == "game.runner: 'nobody' is no creature here (you, other)"
    )
    assert one_line(level(at=(0.3, 0.0))) == (
        "creatures[0].position: starts at the flag: start it away"
    )
    del_flag = level()
    del del_flag["game"]["flag"]
    assert one_line(del_flag) == "game.flag: is required"


def test_a_level_plays_one_mode() -> None:
    both = level()
    both["plugins"].update({"flee": {}, "herding": {}})
    assert one_line(both) == (
        "plugins.herding: plays another game mode than game.mode 'race': turn it off"
    )


def test_the_mode_s_defaults_are_filled_and_the_bundled_levels_are_valid() -> None:
    from ecs_tentacles.race.game import RaceGame

    with World.from_scene(level()) as world:
        race = world.resource(RaceGame)
        assert (race.radius, race.rivals_wait, race.level) == (0.5, 0.0, "test race")
    for name in ("race_1_rock", "race_2_wall"):
        assert load_scene(bundled_scene(name))["game"]["mode"] == "race"


def test_every_entry_of_a_race_world_is_its_owners() -> None:
    from tests.test_registry import strangers

    with World.from_scene(bundled_scene("race_2_wall")) as world:
        assert strangers(world) == []
        assert len(world.registry(GameModes)) == 1
