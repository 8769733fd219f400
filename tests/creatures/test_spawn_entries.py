"""What a spawn accepts: its entry checked among the world's creatures (and game), its
placement, a taken spot or name; refused in one line naming the field, nothing built."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

from ecs_tentacles.components import Transform
from ecs_tentacles.creatures.spawning import SpawnError
from ecs_tentacles.world import World
from tests.creatures.spawn_scenes import APART, creature_entry, scene_of


def test_a_spawn_onto_a_creature_is_refused_in_one_line_or_moved():
    with World.from_scene(scene_of(APART)) as world:
        with pytest.raises(SpawnError) as refused:
            world.spawn(creature_entry("d", 0.1))
        (line,) = str(refused.value).splitlines()
        assert "overlaps creature 'a'" in line and "on_overlap='move'" in line
        assert len(world.physics) == 3  # nothing was built
        seen = []
        world.events.on("creature_spawned", lambda **e: seen.append(e))
        moved = world.spawn(creature_entry("d", 0.1), on_overlap="move")
        (event,) = seen
        assert event["creature"] == moved and event["moved_to"] is not None
        x, y = event["moved_to"][:2]
        assert np.hypot(x - 0.1, y) > 0.3
        assert world.component(moved, Transform).pos[0] == pytest.approx(x, abs=0.01)
        world.step(20)
        assert world.physics.health.recoveries == 0


def test_a_bad_creature_entry_names_the_field_in_one_line():
    with World.from_scene(scene_of(APART)) as world:
        with pytest.raises(SpawnError) as bad:
            world.spawn({"name": "d", "position": [20, 0], "tentacles": {"count": 0}})
        assert str(bad.value).startswith("creature.tentacles.count:")
        with pytest.raises(SpawnError, match=r"^creature: must be an object"):
            world.spawn(["not", "a", "creature"])  # type: ignore[arg-type]
        with pytest.raises(KeyError, match="not a creature"):
            world.despawn(10_000)
        assert len(world.physics) == 3


@pytest.mark.parametrize("bad", [float("nan"), float("inf"), -float("inf")])
def test_a_position_or_heading_that_is_not_finite_is_refused(bad: float):
    """NaN passes every numeric bound; spawned, it froze the creature after three blow-ups."""
    with World.from_scene(scene_of(APART)) as world:
        with pytest.raises(SpawnError, match=r"^creature.position\[0\]: must be a finite number"):
            world.spawn(creature_entry("d", 20.0), position=(bad, 0.0))
        with pytest.raises(SpawnError, match=r"^creature.heading_deg: must be a finite number"):
            world.spawn(creature_entry("d", 20.0), heading_deg=bad)
        assert len(world.physics) == 3


def test_a_taken_name_gets_a_suffix():
    with World.from_scene(scene_of(APART)) as world:
        first = world.spawn(creature_entry("a", 20.0))
        second = world.spawn(creature_entry("a", 26.0))
        assert world.creature_name(first) == "a_2"
        assert world.creature_name(second) == "a_3"


def test_a_spawn_works_out_the_creatures_layout_once(
    make_world: Callable[..., World], monkeypatch: pytest.MonkeyPatch
) -> None:
    """The physical checks' layout is the one the spot is checked with and the creature
    is built from (it was worked out two or three times a spawn)."""
    from ecs_tentacles.creatures import body, spawning
    from ecs_tentacles.scene import construction, layouts, physical

    calls: list[str] = []
    real = construction.creature_layout

    def counted(*args: Any, **kwargs: Any) -> Any:
        calls.append("layout")
        return real(*args, **kwargs)

    for module in (spawning, body, layouts, physical):
        monkeypatch.setattr(module, "creature_layout", counted, raising=False)
    world = make_world("octopus")
    calls.clear()  # building the scene's own creature
    new = {"tentacles": {"count": 3, "links": 3}}
    world.spawn({**new, "name": "a"}, position=(4.0, 4.0))
    assert calls == ["layout"]
    calls.clear()
    world.spawn({**new, "name": "b"}, position=(4.0, 4.0), on_overlap="move")  # on "a"
    free = len(calls)
    assert free >= 2  # the checks' (the taken spot's), then spots on rings until a free one
    calls.clear()
    world.spawn({**new, "name": "c"}, position=(-4.0, -4.0), on_overlap="move")  # free
    assert calls == ["layout"]


def test_a_misspelt_placement_is_refused_not_dropped():
    with World.from_scene(scene_of(APART[:1]), threads=1) as world:
        with pytest.raises(TypeError, match="'positon'"):
            world.spawn(creature_entry("d", 30.0), positon=(30.0, 0.0))
        assert len(world.physics) == 1  # nothing built
        made = world.spawn(creature_entry("d", 0.0), position=(30.0, 0.0), heading_deg=90.0)
        assert world.creature_specs[made]["position"] == [30.0, 0.0]
        assert world.creature_specs[made]["heading_deg"] == 90.0


@pytest.mark.parametrize("level", ["herding_1_field", "race_1_rock"])
def test_a_creature_spawns_into_a_game_level(level: str) -> None:
    """The entry is checked among the level's creatures and game: it was checked in a
    scene of its own, which has no `game`, and refused ("game: required")."""
    with World.from_scene(level, threads=1) as world:
        before = len(world.physics)
        made = world.spawn(creature_entry("visitor", 0.0), position=(20.0, 20.0), on_overlap="move")
        assert len(world.physics) == before + 1
        assert world.creature_name(made) == "visitor"
        world.step(2)


def test_a_bad_entry_names_its_fields_from_creature() -> None:
    with World.from_scene(scene_of(APART[:1]), threads=1) as world:
        with pytest.raises(SpawnError) as raised:
            world.spawn({"name": "x", "tentacles": {"count": 0, "links": 3, "ovverrides": []}})
        count, unknown = raised.value.problems
        assert count == "creature.tentacles.count: must be in [1, 16], got 0"
        assert unknown.startswith("creature.tentacles.ovverrides: unknown key (allowed: count,")
        with pytest.raises(SpawnError) as raised:
            world.spawn({"name": "y", "tentacles": {"count": 3, "overrides": [{"index": 5}]}})
        assert raised.value.problems == [
            "creature.tentacles.overrides[0].index: must be < count (3), got 5"
        ]
        with pytest.raises(SpawnError) as raised:
            world.spawn({"name": "z", "mantle": {"height": 0.001}}, position=(9.0, 9.0))
        assert raised.value.problems[0].startswith("creature.mantle: is too flat to simulate")
        assert len(world.physics) == 1
