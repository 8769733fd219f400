"""Named events (`goal_reached`, `sucker_attached`, ...) with handlers and counts.

Events are for things that happen now and then, never for per-frame state. Every
event is counted; handlers run immediately, in the order they were added.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable
from typing import Any

Handler = Callable[..., None]


class Events:
    """A tiny synchronous event bus."""

    def __init__(self) -> None:
        self._handlers: dict[str, list[Handler]] = {}
        self.counts: Counter[str] = Counter()

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
        for handler in list(self._handlers.get(name, ())):
            handler(**payload)
