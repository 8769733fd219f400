"""Events (`goal_reached`, `sucker_attached`, ...) with handlers and counts.

Each kind of event is a dataclass (`Event`; its `name` is the kind's name): core's
kinds are here (`SuckerReleased`, `CreatureRecovered`, `CreatureFrozen`,
`CreatureSpawned`, `CreatureDespawned`), a feature's in its package (locomotion:
`GoalReached`, `SuckerAttached`); a kind about one creature or one sucker subclasses
`CreatureEvent` or `SuckerEvent`, which declare that entity's field. Handlers subscribe
by kind, getting the event (`world.events.on(GoalReached, handler)`), or by name, getting
its fields as keyword arguments (`world.events.on("goal_reached", handler)`: a script
need import nothing).

Events are for things that happen now and then, never for per-frame state. Every
event is counted by name; handlers run immediately, in the order they were added,
except while `held()`: then they run when the hold ends (a restore holds them, so a
handler that spawns cannot change the world half-way through it).
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, fields
from typing import ClassVar

Handler = Callable[..., None]


@dataclass(frozen=True)
class Event:
    """An event: subclass it, one dataclass per kind, with the kind's `name`."""

    name: ClassVar[str] = ""
    world: object

    def payload(self) -> dict[str, object]:
        """Its fields by name (what a handler subscribed by name gets)."""
        return {f.name: getattr(self, f.name) for f in fields(self)}


@dataclass(frozen=True)
class CreatureEvent(Event):
    """An event about one creature: `creature`, its entity (the field after `world`)."""

    creature: int


@dataclass(frozen=True)
class SuckerEvent(Event):
    """An event about one sucker: `sucker`, its entity (the field after `world`)."""

    sucker: int


@dataclass(frozen=True)
class SuckerReleased(SuckerEvent):
    """A sucker let go: `reason` command, stretch, reach, recovery, despawn, replayed."""

    name: ClassVar[str] = "sucker_released"
    reason: str


@dataclass(frozen=True)
class CreatureRecovered(CreatureEvent):
    """The health check put a creature back to a good state (`cause`: what failed)."""

    name: ClassVar[str] = "creature_recovered"
    cause: str


@dataclass(frozen=True)
class CreatureFrozen(CreatureEvent):
    """A creature failed too often and is frozen (`cause`: the last failure)."""

    name: ClassVar[str] = "creature_frozen"
    cause: str


@dataclass(frozen=True)
class CreatureSpawned(CreatureEvent):
    """A creature joined the world (`moved_to`: where it went if its spot was taken)."""

    name: ClassVar[str] = "creature_spawned"
    creature_name: str
    moved_to: tuple[float, ...] | None


@dataclass(frozen=True)
class CreatureDespawned(CreatureEvent):
    """A creature left the world."""

    name: ClassVar[str] = "creature_despawned"
    creature_name: str


class Events:
    """A tiny synchronous event bus."""

    def __init__(self) -> None:
        self._handlers: dict[str, list[Handler]] = {}  # by name: get keyword arguments
        self._typed: dict[str, list[Handler]] = {}  # by kind: get the event
        self.counts: Counter[str] = Counter()
        self._held: list[Event] | None = None

    def on(self, kind: str | type[Event], handler: Handler) -> Handler:
        """Call `handler` whenever an event of `kind` happens: with the event when `kind`
        is its class, with its fields as keyword arguments when `kind` is its name.
        Returns the handler."""
        if isinstance(kind, str):
            self._handlers.setdefault(kind, []).append(handler)
        else:
            self._typed.setdefault(kind.name, []).append(handler)
        return handler

    def off(self, kind: str | type[Event], handler: Handler) -> None:
        """Stop calling `handler` for `kind`."""
        if isinstance(kind, str):
            self._handlers.get(kind, []).remove(handler)
        else:
            self._typed.get(kind.name, []).remove(handler)

    def emit(self, event: Event) -> None:
        """Count the event and call its handlers."""
        self.counts[event.name] += 1
        if self._held is not None:
            self._held.append(event)
            return
        self._deliver(event)

    def _deliver(self, event: Event) -> None:
        for handler in list(self._typed.get(event.name, ())):
            handler(event)
        handlers = list(self._handlers.get(event.name, ()))
        if handlers:
            payload = event.payload()
            for handler in handlers:
                handler(**payload)

    @contextmanager
    def held(self) -> Iterator[None]:
        """Inside, events are counted but their handlers wait; they run, in order, when
        the block ends (also when it raised: what it emitted did happen)."""
        if self._held is not None:  # already held: the outer hold delivers
            yield
            return
        self._held = []
        try:
            yield
        finally:
            waiting, self._held = self._held, None
            for event in waiting:
                self._deliver(event)
