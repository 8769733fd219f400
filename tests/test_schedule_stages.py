"""Stages, ordering against absent systems, replace, disable and the data-flow table."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from ecs_tentacles.schedule import Schedule, ScheduleError, ScheduleWarning
from ecs_tentacles.system import System
from ecs_tentacles.world import World
from tests.conftest import NO_LOCOMOTION, creature_scene


def make(
    name: str,
    stage: str | None = None,
    after: tuple[str, ...] = (),
    before: tuple[str, ...] = (),
    writes: tuple[str, ...] = (),
) -> System:
    attrs = {"name": name, "stage": stage, "after": after, "before": before, "writes": writes}
    return type(name, (System,), attrs)()


def test_stages_run_in_order_whatever_the_order_added() -> None:
    schedule = Schedule()
    schedule.add(make("out", "output"), make("late", "animate"), make("first", "decide"))
    assert schedule.names == ["first", "late", "out"]


def test_ordering_against_an_absent_system_is_a_no_op() -> None:
    schedule = Schedule()
    schedule.add(make("a", "act", after=("render", "record"), before=("nothing",)))
    assert schedule.names == ["a"]


def test_a_system_without_a_stage_joins_the_stage_of_what_it_follows() -> None:
    schedule = Schedule()
    schedule.add(make("sync", "sync"), make("watch", after=("sync",)), make("lone"))
    assert schedule.stage_of("watch") == "sync"
    assert schedule.stage_of("lone") == "act"
    assert schedule.names == ["lone", "sync", "watch"]


def test_ordering_against_the_stages_is_refused() -> None:
    schedule = Schedule()
    schedule.add(make("physics", "physics"))
    with pytest.raises(ScheduleError, match=r"'early' .stage decide. cannot run after 'physics'"):
        schedule.add(make("early", "decide", after=("physics",)))
    with pytest.raises(ScheduleError, match="stage must be one of decide, act"):
        schedule.add(make("odd", "later"))


def test_remove_replace_and_disable_a_builtin(make_world: Callable[..., World]) -> None:
    scene = creature_scene(count=3, links=2)
    scene["creatures"][0]["goals"] = [{"position": [1.0, 0.0]}]
    world = make_world(scene)
    world.schedule.remove("tentacle_selection")  # action_queue named it: still fine
    assert "tentacle_selection" not in world.schedule.names

    class StillGoals(System):
        name = "still_goals"

        def process(self, world: World, dt: float) -> None:
            world.stores["locomotion.creatures"].has_goal[:] = False

    old = world.schedule.replace("goals", StillGoals())
    assert old.name == "goals"
    assert world.schedule.names[0] == "goals"  # the new one, in the old place and stage
    assert isinstance(world.schedule["goals"], StillGoals)
    world.schedule.disable("rig")
    assert "rig" not in world.schedule.names and world.schedule.disabled() == ["rig"]
    assert "rig (disabled)" in world.schedule.table()
    world.step(5)
    assert not world.stores["locomotion.creatures"].has_goal.any()
    world.schedule.enable("rig")
    assert world.schedule.names[-1] == "rig"


def test_disabled_system_does_not_run(make_world: Callable[..., World]) -> None:
    world = make_world(creature_scene(count=3, links=2), plugins=NO_LOCOMOTION)
    before = world.transforms.pos.copy()
    world.schedule.disable("physics")
    world.step(10)
    np.testing.assert_array_equal(world.transforms.pos, before)


def test_unordered_writers_of_one_field_are_warned_about() -> None:
    schedule = Schedule()
    schedule.add(make("a", "act", writes=("motors.target",)))
    with pytest.warns(ScheduleWarning, match="'a' and 'b' both write 'motors.target'"):
        schedule.add(make("b", "act", writes=("motors.target", "motors.gain")))
    assert schedule.conflicts == [("motors.target", "a", "b")]


def test_ordered_writers_and_writers_in_other_stages_are_fine(
    recwarn: pytest.WarningsRecorder,
) -> None:
    schedule = Schedule()
    schedule.add(make("a", "act", writes=("motors.target",)))
    schedule.add(make("b", "act", after=("a",), writes=("motors.target",)))
    schedule.add(make("c", "animate", writes=("motors.target",)))
    assert schedule.conflicts == []
    assert not [w for w in recwarn if issubclass(w.category, ScheduleWarning)]


def test_builtins_have_no_unordered_writers(make_world: Callable[..., World]) -> None:
    world = make_world(creature_scene(count=3, links=2))
    assert world.schedule.conflicts == []
    rows = {row["system"]: row for row in world.schedule.rows()}
    assert rows["motor_targets"]["plugin"] == "locomotion"
    assert rows["motor_targets"]["writes"] == "motors.{target, gain}"
    assert rows["physics"]["plugin"] == "core"
