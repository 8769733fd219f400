"""Named events (`goal_reached`, `sucker_attached`, ...) with handlers and counts.

Events are for things that happen now and then, never for per-frame state. Every
event is counted; handlers run immediately, in the order they were added, except
while `held()`: then they run when the hold ends (a restore holds them, so a handler
that spawns cannot change the world half-way through it).
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

Handler = Callable[..., None]


class Events:
    """A tiny synchronous event bus."""

    def __init__(self) -> None:
        self._handlers: dict[str, list[Handler]] = {}
        self.counts: Counter[str] = Counter()
        self._held: list[tuple[str, dict[str, Any]]] | None = None

    def on(self, name: str, handler: Handler) -> Handler:
        """Call `handler(**payload)` whenever `name` is emitted; returns the handler."""
        self._handlers.setdefault(name, []).append(handler)
        return handler

    def off(self, name: str, handler: Handler) -> None:
        """Stop calling `handler` for `name`."""
        self._handlers.get(name, []).remove(handler)

    def emit(self, name: str, **payload: Any) -> None:
        """Count the event and call its handlers with `payload`."""
        self.counts[name] += 1
        if self._held is not None:
            self._held.append((name, payload))
            return
        for handler in list(self._handlers.get(name, ())):
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
            for name, payload in waiting:
                for handler in list(self._handlers.get(name, ())):
                    handler(**payload)
