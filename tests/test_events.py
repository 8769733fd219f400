"""Typed events: one dataclass per kind, subscribed by class (the event) or by name (its
fields as keyword arguments, for scripts), counted by name, held during a restore."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from ecs_tentacles.events import CreatureSpawned, Events, SuckerReleased
from ecs_tentacles.locomotion.events import GoalReached
from ecs_tentacles.world import World


def test_by_class_the_event_by_name_its_fields_both_counted_once() -> None:
    events = Events()
    typed: list[SuckerReleased] = []
    named: list[dict[str, Any]] = []
    events.on(SuckerReleased, typed.append)
    events.on("sucker_released", lambda **fields: named.append(fields))
    released = SuckerReleased(world=None, sucker=7, reason="stretch")
    events.emit(released)
    assert typed == [released] and named == [{"world": None, "sucker": 7, "reason": "stretch"}]
    assert events.counts["sucker_released"] == 1
    events.off(SuckerReleased, typed.append)
    events.emit(released)
    assert len(typed) == 1 and len(named) == 2


def test_held_events_wait_then_arrive_in_order() -> None:
    events = Events()
    seen: list[str] = []
    events.on(SuckerReleased, lambda e: seen.append(e.reason))
    with events.held():
        events.emit(SuckerReleased(None, 1, "first"))
        events.emit(SuckerReleased(None, 2, "second"))
        assert seen == [] and events.counts["sucker_released"] == 2
    assert seen == ["first", "second"]


def test_a_world_emits_its_kinds(make_world: Callable[..., World]) -> None:
    world = make_world("octopus")
    reached: list[GoalReached] = []
    world.events.on(GoalReached, reached.append)
    spawned: list[CreatureSpawned] = []
    world.events.on(CreatureSpawned, spawned.append)
    world.spawn({"name": "newcomer", "tentacles": {"count": 3, "links": 3}}, position=(3, 3))
    assert [e.creature_name for e in spawned] == ["newcomer"]
    world.step(60 * 15)
    (first, *_) = reached  # octopus.json's creature reaches its goal within 15 s
    assert first.name == "goal_reached" and first.world is world
    assert world.creature_name(first.creature) == "octopus" and first.position.shape == (3,)
