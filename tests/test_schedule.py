"""The frame order: declared by name, resolved once, visible and exact."""

from __future__ import annotations

from collections.abc import Callable
from typing import ClassVar

import pytest

from ecs_tentacles.schedule import Schedule, ScheduleError
from ecs_tentacles.system import System
from ecs_tentacles.world import World
from tests.conftest import NO_LOCOMOTION, creature_scene


def named(name: str, after: tuple[str, ...] = (), before: tuple[str, ...] = ()) -> System:
    cls = type(name, (System,), {"name": name, "after": after, "before": before})
    return cls()


class Probe(System):
    """Records each call as (frame, name) and each substep as (frame, 'substep', i)."""

    log: ClassVar[list[tuple[object, ...]]] = []

    def process(self, world: World, dt: float) -> None:
        self.log.append((world.frame, self.name))


class SubstepProbe(Probe):
    name = "substep_probe"
    before = ("physics",)

    def substep(self, world: World, index: int, dt: float) -> None:
        self.log.append((world.frame, "substep", index))


class Early(Probe):
    name = "early"
    before = ("physics",)


class Late(Probe):
    name = "late"
    after = ("physics_sync",)


# without locomotion's plugins (NO_LOCOMOTION) the frame is these
PHYSICS_ON = [
    "physics",
    "lod_replay",
    "physics_sync",
    "physics_health",
    "threats",
    "emotion",
    "rig",
]
BUILTIN = [
    "goals",
    "avoidance",
    "tentacle_selection",
    "action_queue",
    "motor_targets",
    "suckers",
    *PHYSICS_ON,
]


def test_builtin_order(make_world: Callable[..., World]) -> None:
    world = make_world(creature_scene(count=3, links=2))
    assert world.schedule.names == BUILTIN
    physics_only = make_world(creature_scene(count=3, links=2), plugins=NO_LOCOMOTION)
    assert physics_only.schedule.names == PHYSICS_ON
    assert [world.schedule.stage_of(n) for n in BUILTIN] == [
        "decide", "decide", "decide", "act", "act", "act", "physics", "physics", "sync", "sync",
        "animate", "animate", "animate",
    ]  # fmt: skip


def test_probe_records_frame_and_substep_order(make_world: Callable[..., World]) -> None:
    world = make_world(creature_scene(count=3, links=2), plugins=NO_LOCOMOTION)
    Probe.log.clear()
    world.add_system(Late())
    world.add_system(SubstepProbe())
    world.add_system(Early())
    # late: after physics_sync, it joins the sync stage, before fur animates
    late_at = PHYSICS_ON.index("physics_health") + 1
    assert world.schedule.names == [
        "substep_probe",
        "early",
        *PHYSICS_ON[:late_at],
        "late",
        *PHYSICS_ON[late_at:],
    ]
    world.step(2)
    substeps = world.settings.substeps
    expected: list[tuple[object, ...]] = []
    for frame in range(2):
        expected += [(frame, "substep_probe"), (frame, "early")]
        expected += [(frame, "substep", i) for i in range(substeps)]
        expected += [(frame, "late")]
    assert Probe.log == expected


def test_constraints_win_then_the_earliest_added_ready_system_runs_first() -> None:
    schedule = Schedule()
    for system in [named("a"), named("b"), named("c", before=("a",)), named("d", after=("b",))]:
        schedule.add(system)
    assert schedule.names == ["b", "c", "a", "d"]


def test_class_priority_attributes_are_ignored() -> None:
    schedule = Schedule()
    first = named("first")
    first.priority = -100  # type: ignore[attr-defined]
    schedule.add(first)
    schedule.add(named("second", before=("first",)))
    assert schedule.names == ["second", "first"]


@pytest.mark.parametrize(
    ("systems", "message"),
    [
        ([named("a"), named("a")], "a system named 'a' is already scheduled"),
        (
            [named("a"), named("b", after=("a",), before=("a",))],
            "systems a, b wait on each other (a cycle)",
        ),
        ([named("")], "has no name"),
    ],
)
def test_bad_places_are_refused(systems: list[System], message: str) -> None:
    schedule = Schedule()
    with pytest.raises(ScheduleError, match=message.replace("(", r"\(").replace(")", r"\)")):
        for system in systems:
            schedule.add(system)


def test_refused_system_leaves_the_schedule_unchanged() -> None:
    schedule = Schedule()
    schedule.add(named("a"))
    with pytest.raises(ScheduleError):
        schedule.add(named("b", after=("a",), before=("a",)))
    assert schedule.names == ["a"] and "b" not in schedule


def test_a_system_orders_against_a_set_another_feature_exports() -> None:
    """`after` / `before` name a set (`System.sets`): every system in it, whatever its
    name, so a behaviour never names another feature's systems."""

    def member(name: str, sets: tuple[str, ...]) -> System:
        return type(name, (System,), {"name": name, "sets": sets, "stage": "decide"})()

    def user(name: str, after: tuple[str, ...], before: tuple[str, ...]) -> System:
        cls = type(name, (System,), {"name": name, "after": after, "before": before})
        return cls()

    schedule = Schedule()
    schedule.add(
        member("pick", ("read",)),
        user("mine", ("settled",), ("read",)),
        member("check", ("settled",)),
        member("also_check", ("settled",)),
    )
    assert schedule.names == ["check", "also_check", "mine", "pick"]
    assert schedule.stage_of("mine") == "decide"  # inferred from the set it runs after
    with pytest.raises(ScheduleError, match="set 'pick' has the name of a system"):
        schedule.add(member("odd", ("pick",)))
    assert "odd" not in schedule.names


def test_the_behaviour_phases_order_the_examples_as_their_names_did(
    make_world: Callable[..., World],
) -> None:
    scene = creature_scene(count=3, links=2)
    scene["plugins"] = {"wander": {}}
    world = make_world(scene)
    names = world.schedule.names
    assert names.index("goals") < names.index("wander") < names.index("tentacle_selection")
    assert names.index("threats") < names.index("emotion")
